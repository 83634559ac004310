// The client side of the simulated lab's HID relay socket (drivers/lamps socket_hid_transport.cpp,
// docs/simulator.md "HID relay socket"): the input is what the board answers, one JSON line per
// request, to the calls HidRelay makes — open (device info, the product name's relay count), a
// feature report sent, the state read back and decoded (hid_relay_protocol.cpp).
#include "colorlab/wire/hid_relay_protocol.hpp"
#include "colorlab/drivers/socket_hid_transport.hpp"
#include "fuzz_support.hpp"
#include "line_peer.hpp"

namespace {

using colorlab::fuzz::typed;

void one_input(const std::uint8_t* data, std::size_t size) {
  static colorlab::fuzz::LinePeer board("hid.sock");
  board.set_answers(colorlab::fuzz::as_text(data, size));
  colorlab::drivers::SocketHidTransport hid(board.path(), std::chrono::milliseconds(2000));
  if (!typed("open", [&] { hid.open(); })) return;
  typed("relay_count_from_product", [&] { (void)colorlab::wire::hidrelay::relay_count_from_product(hid.info().product); });
  if (!typed("send_feature_report", [&] { hid.send_feature_report(colorlab::wire::hidrelay::switch_one(1, true)); })) return;
  typed("get_feature_report", [&] {
    auto bytes = hid.get_feature_report(0, colorlab::wire::hidrelay::kReportDataBytes);
    if (bytes.size() != colorlab::wire::hidrelay::kReportDataBytes) {
      std::fprintf(stderr, "fuzz: asked for %zu data bytes, got %zu\n", colorlab::wire::hidrelay::kReportDataBytes, bytes.size());
      std::abort();
    }
    (void)colorlab::wire::hidrelay::parse_state(bytes);
  });
}

}  // namespace

COLORLAB_FUZZ_TARGET("hid_socket", one_input)
