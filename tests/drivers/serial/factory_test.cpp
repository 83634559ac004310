// The factory builds the new kinds from their config entries (colorlabd.toml or colorlab-sim's
// announcement) and refuses invalid options with a typed error naming the instrument.
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/enttec_dmx.hpp"
#include "colorlab/drivers/factory.hpp"
#include "colorlab/drivers/hid_relay.hpp"
#include "colorlab/drivers/spectrolino.hpp"

namespace colorlab::test {
namespace {

using drivers::InstrumentConfig;

TEST(DriverFactory, BuildsSpectrolinoDmxAndRelay) {
  boost::asio::io_context io;
  auto spectro = drivers::make_instrument(
      io.get_executor(), InstrumentConfig{
                             "sp",
                             "spectrolino",
                             "/dev/pts/9",
                             true,
                             {{"illuminant", "D65"}, {"observer", 10}, {"power_on_baud", 9600}, {"table", true}},
                         });
  ASSERT_NE(dynamic_cast<drivers::Spectrolino*>(spectro.get()), nullptr);
  EXPECT_EQ(spectro->identity().kind, "spectrolino");
  EXPECT_TRUE(spectro->identity().simulated);

  // colorlab-sim's announcement: one channel map including the dimmer.
  auto dmx = drivers::make_instrument(
      io.get_executor(),
      InstrumentConfig{"cab", "dmx", "/dev/pts/8", true, {{"channels", {{"D65", 1}, {"TL84", 2}, {"dimmer", 6}}}}});
  auto* d = dynamic_cast<drivers::EnttecDmx*>(dmx.get());
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->lamp_names(), (std::vector<std::string>{"D65", "TL84"}));
  EXPECT_DOUBLE_EQ(d->level("dimmer"), 0.0);

  auto relay = drivers::make_instrument(io.get_executor(),
                                        InstrumentConfig{"rl", "hidrelay", "auto", false, {{"lamps", {{"D65", 1}, {"A", 2}}}}});
  ASSERT_NE(dynamic_cast<drivers::HidRelay*>(relay.get()), nullptr);
  auto kinds = drivers::known_instrument_kinds();
  for (const char* k : {"ls110", "spectrolino", "dmx", "hidrelay"}) {
    EXPECT_NE(std::find(kinds.begin(), kinds.end(), k), kinds.end()) << k;
  }
}

TEST(DriverFactory, BadOptionsAreTypedErrors) {
  boost::asio::io_context io;
  auto expect_bad = [&](InstrumentConfig c) {
    try {
      drivers::make_instrument(io.get_executor(), c);
      ADD_FAILURE() << "accepted " << c.options.dump();
    } catch (const Error& e) {
      EXPECT_EQ(e.cls(), ErrorClass::bad_parameter) << e.what();
    }
  };
  expect_bad({"sp", "spectrolino", "/dev/x", false, {{"illuminant", "D99"}}});
  expect_bad({"sp", "spectrolino", "/dev/x", false, {{"observer", 5}}});
  expect_bad({"sp", "spectrolino", "/dev/x", false, {{"max_baud", "fast"}}});
  expect_bad({"cab", "dmx", "/dev/x", false, {}});
  expect_bad({"cab", "dmx", "/dev/x", false, {{"lamps", {{"D65", 600}}}}});
  expect_bad({"rl", "hidrelay", "auto", false, {{"lamps", {{"D65", 9}}}}});
}

}  // namespace
}  // namespace colorlab::test
