// Enttec DMX USB Pro framing (drivers/wire): a byte stream as the driver and the simulated widget
// receive it — fed to the incremental FrameParser in two chunks (the first byte chooses where the
// stream is split, as a serial read would split it), every frame through each label's decoder —
// and the whole input as one frame through decode_frame.
#include "colorlab/wire/enttec_dmx_protocol.hpp"
#include "fuzz_support.hpp"

namespace {

namespace dmx = colorlab::wire::enttec;
using colorlab::fuzz::typed;

void frame_decoders(const dmx::Frame& f) {
  typed("decode_get_parameters_request", [&] { (void)dmx::decode_get_parameters_request(f); });
  typed("decode_parameters_reply", [&] { (void)dmx::get_parameters_reply(dmx::decode_parameters_reply(f)); });
  typed("decode_set_parameters_request",
        [&] { (void)dmx::set_parameters_request(dmx::decode_set_parameters_request(f)); });
  typed("decode_send_dmx", [&] {
    auto p = dmx::decode_send_dmx(f);
    (void)dmx::send_dmx_request(p.slots, p.start_code);
  });
  typed("decode_serial_reply", [&] { (void)dmx::serial_reply(dmx::decode_serial_reply(f)); });
}

void one_input(const std::uint8_t* data, std::size_t size) {
  std::span<const std::uint8_t> bytes(data, size);
  typed("decode_frame", [&] { frame_decoders(dmx::decode_frame(bytes)); });
  if (bytes.empty()) return;
  const std::size_t split = std::min<std::size_t>(bytes[0], bytes.size() - 1);
  dmx::FrameParser parser;
  for (auto chunk : {bytes.subspan(1, split), bytes.subspan(1 + split)}) {
    std::vector<dmx::Frame> frames;
    typed("FrameParser::feed", [&] { frames = parser.feed(chunk); });
    for (const auto& f : frames) frame_decoders(f);
  }
}

}  // namespace

COLORLAB_FUZZ_TARGET("dmx_wire", one_input)
