#pragma once
// Enttec DMX USB Pro widget framing (instrument-protocols.md §3a): 7E, label, length LSB, length
// MSB (0..600), data, E7; no checksum. Pure functions shared by the driver, simulator and tests.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "colorlab/core/error.hpp"

namespace colorlab::wire::enttec {

using Bytes = std::vector<std::uint8_t>;

inline constexpr std::uint8_t kStart = 0x7E;
inline constexpr std::uint8_t kEnd = 0xE7;
inline constexpr std::size_t kMaxPayload = 600;
inline constexpr std::size_t kMaxSlots = 512;
inline constexpr std::uint8_t kDmxStartCode = 0x00;

namespace label {
inline constexpr std::uint8_t ReprogramFirmware = 1, ProgramFlashPage = 2, GetWidgetParameters = 3,
                              SetWidgetParameters = 4, ReceivedDmx = 5, SendDmx = 6, SendRdm = 7,
                              ReceiveDmxOnChange = 8, ReceivedDmxChange = 9, GetSerialNumber = 10,
                              SendRdmDiscovery = 11, RdmTimeout = 12, ManufacturerName = 77, DeviceName = 78;
}  // namespace label

struct Frame {
  std::uint8_t label = 0;
  Bytes payload;
};

// Throws Error{bad_parameter} when the payload exceeds 600 bytes.
Bytes encode_frame(std::uint8_t label, std::span<const std::uint8_t> payload);
// Decodes exactly one complete frame. Throws Error{coms_fail} for a missing 7E/E7 or a length
// that disagrees with the buffer, Error{protocol_error} for a length over 600.
Frame decode_frame(std::span<const std::uint8_t> bytes);

// Incremental receiver for a byte stream: skips bytes until a 7E, drops frames whose length is over
// 600 or whose end byte is not E7 (as OLA does), and counts what it dropped.
class FrameParser {
 public:
  std::vector<Frame> feed(std::span<const std::uint8_t> bytes);
  std::size_t dropped_bytes() const { return dropped_bytes_; }
  std::size_t bad_frames() const { return bad_frames_; }
  const std::string& last_problem() const { return last_problem_; }
  bool mid_frame() const { return !buf_.empty(); }
  void reset() { buf_.clear(); }

 private:
  Bytes buf_;
  std::size_t dropped_bytes_ = 0;
  std::size_t bad_frames_ = 0;
  std::string last_problem_;
};

// A widget's firmware version as its label 3 reply carries it: LSB the minor, MSB the major number
// (1 = DMX, 2 = RDM, 3 = sniffer firmware), each a plain binary number that OLA and our driver print
// in decimal, so spec 1.44 firmware is minor 44 (0x2C), major 1 — not the BCD-looking 0x0144 (1.68).
constexpr std::uint16_t firmware_version(std::uint8_t major, std::uint8_t minor) {
  return static_cast<std::uint16_t>(major << 8 | minor);
}

// Label 3 reply / label 4 request body.
struct WidgetParameters {
  std::uint16_t firmware = firmware_version(1, 44);
  std::uint8_t break_time = 9;    // units of 10.67 us, 9..127
  std::uint8_t mab_time = 1;      // units of 10.67 us, 1..127
  std::uint8_t output_rate = 40;  // packets/s, 0..40 (0 = as fast as possible)
  Bytes user_config;
};

Bytes get_parameters_request(std::uint16_t user_config_size = 0);  // label 3 frame
std::uint16_t decode_get_parameters_request(const Frame& f);       // user-config size
Bytes get_parameters_reply(const WidgetParameters& p);             // label 3 frame
WidgetParameters decode_parameters_reply(const Frame& f);
Bytes set_parameters_request(const WidgetParameters& p);  // label 4 frame (no reply)
// Throws Error{bad_parameter} when break/MAB/rate are outside the spec ranges.
WidgetParameters decode_set_parameters_request(const Frame& f);

// Label 6: start code then up to 512 slot values, slot 1 first.
Bytes send_dmx_request(std::span<const std::uint8_t> slots, std::uint8_t start_code = kDmxStartCode);
struct DmxPacket {
  std::uint8_t start_code = 0;
  Bytes slots;
};
DmxPacket decode_send_dmx(const Frame& f);

Bytes get_serial_request();                // label 10, no payload
Bytes serial_reply(std::uint32_t serial);  // label 10, 4 bytes little-endian (BCD digits)
std::uint32_t decode_serial_reply(const Frame& f);
// A decimal serial such as 12345678 as the BCD value the widget stores (0x12345678).
std::uint32_t bcd_serial(std::uint32_t decimal);

std::string to_hex(std::span<const std::uint8_t> bytes);  // "7E 06 ..." for transcripts

}  // namespace colorlab::wire::enttec
