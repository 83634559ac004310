// The simulated DMX USB Pro identified the way OLA 0.10 identifies a widget, from the raw reply bytes
// and without colorlab's codec, so the simulator cannot agree with the driver on a wrong encoding
// (issue 25: it sent firmware 1.44 as 0x0144, which OLA and the driver both print as 1.68).
// OLA's behaviour reproduced here, from OpenLightingProject/ola at tag 0.10.9 (Debian's `ola`):
//   plugins/usbpro/UsbProWidgetDetector.cpp  the probe order 77, 78, 10, 3 (data: a zero uint16), 14;
//     HandleSerialResponse: 4 bytes, little-endian; HandleGetParams: a struct {firmware_lo, firmware_hi,
//     break_time, mab_time, output_rate}, firmware = (firmware_hi << 8) + firmware_lo
//   plugins/usbpro/UsbProDevice.cpp  the device name: "firmware " << (fw >> 8) << "." << (fw & 0xff);
//     SerialToString: the four serial bytes from the last, each as two BCD digits
// and the Enttec "DMX USB Pro Widget API Specification 1.44" (instrument-protocols.md §3a): firmware LSB then MSB.
#include <gtest/gtest.h>

#include <cstdint>
#include <sstream>
#include <string>

#include "sim_process.hpp"

using colorlab::test::SerialClient;
using colorlab::test::SimProcess;

namespace {

std::string frame(std::uint8_t label, std::string data = {}) {
  std::string f{'\x7E', static_cast<char>(label), static_cast<char>(data.size() & 0xFF), static_cast<char>(data.size() >> 8)};
  return f + data + '\xE7';
}

// The data bytes of the one reply frame `raw` holds, checked against the framing OLA's receiver accepts.
std::string reply_data(const std::string& raw, std::uint8_t label) {
  EXPECT_GE(raw.size(), 5u);
  if (raw.size() < 5) return {};
  EXPECT_EQ(static_cast<std::uint8_t>(raw[0]), 0x7E);
  EXPECT_EQ(static_cast<std::uint8_t>(raw[1]), label);
  std::size_t len = static_cast<std::uint8_t>(raw[2]) | static_cast<std::size_t>(static_cast<std::uint8_t>(raw[3])) << 8;
  EXPECT_EQ(raw.size(), len + 5);
  EXPECT_EQ(static_cast<std::uint8_t>(raw.back()), 0xE7);
  return raw.substr(4, len);
}

unsigned byte(const std::string& s, std::size_t i) { return static_cast<std::uint8_t>(s[i]); }

}  // namespace

TEST(SimDmxAsOlaSeesIt, SerialAndFirmwareFromTheRawReplyBytes) {
  SimProcess sim("[dmx]\nserial = 12345678\n[ls110]\nenabled = false\n[spectrolino]\nenabled = false\n");
  SerialClient c(sim.port("dmx"), 115200);

  // OLA's USB Protocol Extensions first: a genuine Enttec widget stays silent, so the first reply
  // on the line (the widget answers in order) must be the serial number's.
  c.write(frame(77));
  c.write(frame(78));
  c.write(frame(10));
  std::string serial = reply_data(c.read_n(9, 5.0), 10);
  ASSERT_EQ(serial.size(), 4u) << "OLA warns and keeps serial 0 unless the reply carries exactly 4 bytes";
  std::ostringstream serial_text;  // SerialToString: bytes 3, 2, 1, 0, each two BCD digits
  for (int i = 3; i >= 0; --i) {
    unsigned b = byte(serial, static_cast<std::size_t>(i));
    serial_text << (b >> 4) << (b & 0x0F);
  }
  EXPECT_EQ(serial_text.str(), "12345678");

  c.write(frame(3, std::string(2, '\0')));
  std::string params = reply_data(c.read_n(10, 5.0), 3);
  ASSERT_GE(params.size(), 5u) << "OLA ignores a GET_PARAMS reply shorter than its 5-byte struct";
  unsigned firmware = (byte(params, 1) << 8) + byte(params, 0);
  std::ostringstream firmware_text;
  firmware_text << (firmware >> 8) << "." << (firmware & 0xff);
  EXPECT_EQ(firmware_text.str(), "1.44") << "docs/simulator.md: the widget runs DMX firmware 1.44";
  EXPECT_EQ(byte(params, 2), 9u) << "break time, units of 10.67 us";
  EXPECT_EQ(byte(params, 3), 1u) << "MAB time, units of 10.67 us";
  EXPECT_EQ(byte(params, 4), 40u) << "output rate, packets/s";

  // OLA's Mk II hardware-version probe: the USB Pro (Mk I) does not answer it, so again the next reply is the serial's.
  c.write(frame(14));
  c.write(frame(10));
  EXPECT_EQ(reply_data(c.read_n(9, 5.0), 10), serial);
}
