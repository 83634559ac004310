// Enttec DMX USB Pro framing against the byte layout in instrument-protocols.md §3a.
#include <gtest/gtest.h>

#include "colorlab/wire/enttec_dmx_protocol.hpp"

namespace en = colorlab::wire::enttec;
using colorlab::Error;
using colorlab::ErrorClass;

TEST(SimWireEnttec, FullUniverseFrameLayout) {
  std::vector<std::uint8_t> slots(512, 0);
  slots[0] = 255;
  slots[4] = 128;
  auto f = en::send_dmx_request(slots);
  ASSERT_EQ(f.size(), 513u + 5u);
  EXPECT_EQ(f[0], 0x7E);
  EXPECT_EQ(f[1], 0x06);
  EXPECT_EQ(f[2], 0x01);  // 513 = 0x0201, LSB first
  EXPECT_EQ(f[3], 0x02);
  EXPECT_EQ(f[4], 0x00);  // start code
  EXPECT_EQ(f[5], 255);
  EXPECT_EQ(f[9], 128);
  EXPECT_EQ(f.back(), 0xE7);
  auto p = en::decode_send_dmx(en::decode_frame(f));
  EXPECT_EQ(p.start_code, 0);
  EXPECT_EQ(p.slots, slots);
}

TEST(SimWireEnttec, ShortFrameAndOtherLabels) {
  std::uint8_t five[] = {1, 2, 3, 4, 5};
  EXPECT_EQ(en::to_hex(en::send_dmx_request(five)), "7E 06 06 00 00 01 02 03 04 05 E7");
  EXPECT_EQ(en::to_hex(en::get_parameters_request()), "7E 03 02 00 00 00 E7");
  EXPECT_EQ(en::to_hex(en::get_serial_request()), "7E 0A 00 00 E7");
  en::WidgetParameters wp;
  EXPECT_EQ(en::to_hex(en::get_parameters_reply(wp)), "7E 03 05 00 2C 01 09 01 28 E7");
  auto back = en::decode_parameters_reply(en::decode_frame(en::get_parameters_reply(wp)));
  EXPECT_EQ(back.firmware >> 8, 1);
  EXPECT_EQ(back.firmware & 0xFF, 44);
  EXPECT_EQ(back.output_rate, 40);
  EXPECT_EQ(en::to_hex(en::serial_reply(en::bcd_serial(12345678))), "7E 0A 04 00 78 56 34 12 E7");
  EXPECT_EQ(en::decode_serial_reply(en::decode_frame(en::serial_reply(0x12345678))), 0x12345678u);
  auto set = en::decode_set_parameters_request(en::decode_frame(en::set_parameters_request({0, 20, 5, 30, {}})));
  EXPECT_EQ(set.break_time, 20);
  EXPECT_EQ(set.mab_time, 5);
  EXPECT_EQ(set.output_rate, 30);
}

TEST(SimWireEnttec, MalformedFramesThrow) {
  auto cls = [](auto&& fn) {
    try {
      fn();
    } catch (const Error& e) {
      return e.cls();
    }
    return ErrorClass::internal;
  };
  std::vector<std::uint8_t> no_end{0x7E, 0x06, 0x01, 0x00, 0x00, 0x7E};
  EXPECT_EQ(cls([&] { en::decode_frame(no_end); }), ErrorClass::coms_fail);
  std::vector<std::uint8_t> too_long{0x7E, 0x06, 0x59, 0x02, 0xE7};  // 601
  EXPECT_EQ(cls([&] { en::decode_frame(too_long); }), ErrorClass::protocol_error);
  std::vector<std::uint8_t> bad_start{0x7F, 0x06, 0x00, 0x00, 0xE7};
  EXPECT_EQ(cls([&] { en::decode_frame(bad_start); }), ErrorClass::coms_fail);
  std::vector<std::uint8_t> big(601, 0);
  EXPECT_EQ(cls([&] { en::encode_frame(6, big); }), ErrorClass::bad_parameter);
  std::vector<std::uint8_t> bad_params{0x7E, 0x04, 0x05, 0x00, 0x00, 0x00, 0x02, 0x01, 0x28, 0xE7};  // break 2
  EXPECT_EQ(cls([&] { en::decode_set_parameters_request(en::decode_frame(bad_params)); }), ErrorClass::bad_parameter);
}

TEST(SimWireEnttec, StreamParserResyncsAndDropsBadFrames) {
  en::FrameParser p;
  std::vector<std::uint8_t> stream{0x00, 0x11};  // noise before a frame
  auto good = en::get_serial_request();
  stream.insert(stream.end(), good.begin(), good.end());
  std::vector<std::uint8_t> bad{0x7E, 0x06, 0x01, 0x00, 0x00, 0x00};  // wrong end byte
  stream.insert(stream.end(), bad.begin(), bad.end());
  std::uint8_t two[] = {9, 8};
  auto dmx = en::send_dmx_request(two);
  // Feed in two pieces to cross a frame boundary.
  stream.insert(stream.end(), dmx.begin(), dmx.end());
  auto first = p.feed(std::span(stream).first(7));
  auto rest = p.feed(std::span(stream).subspan(7));
  first.insert(first.end(), rest.begin(), rest.end());
  ASSERT_EQ(first.size(), 2u);
  EXPECT_EQ(first[0].label, 10);
  EXPECT_EQ(en::decode_send_dmx(first[1]).slots, (std::vector<std::uint8_t>{9, 8}));
  EXPECT_EQ(p.bad_frames(), 1u);
  EXPECT_EQ(p.dropped_bytes(), 2u + 6u);
}
