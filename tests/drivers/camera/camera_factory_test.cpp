// The factory's camera kinds: `gphoto2` (the real tethered DSLR through libgphoto2) and `simdslr`
// (the simulated lab's DSLR over its socket) become CameraInstruments; with no camera and no
// simulator on this machine, connecting them is a typed error that says what to do, never a hang.
#include <gtest/gtest.h>

#include <algorithm>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/use_future.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/camera/camera_instrument.hpp"
#include "colorlab/drivers/factory.hpp"

namespace cam = colorlab::drivers::camera;
using colorlab::Error;
using colorlab::ErrorClass;
using colorlab::drivers::InstrumentConfig;

namespace {

Error connect_error(boost::asio::io_context& io, colorlab::drivers::Instrument& instrument) {
  auto done = boost::asio::co_spawn(io, instrument.connect(), boost::asio::use_future);
  io.restart();
  io.run();
  try {
    done.get();
  } catch (const Error& e) {
    return e;
  }
  ADD_FAILURE() << instrument.id() << " connected, but there is no such device here";
  return Error(ErrorClass::internal, "connected");
}

}  // namespace

TEST(camera_factory, gphoto2_kind_is_a_camera_instrument_and_no_camera_is_a_typed_error) {
  boost::asio::io_context io;
  auto instrument = colorlab::drivers::make_instrument(
      io.get_executor(), InstrumentConfig{"eos", "gphoto2", "auto", false, {{"model", "Canon EOS 20D (normal mode)"}, {"call_timeout_ms", 20000}}});
  auto* camera = dynamic_cast<cam::CameraInstrument*>(instrument.get());
  ASSERT_NE(camera, nullptr);
  EXPECT_EQ(instrument->capabilities(), std::vector<colorlab::drivers::Capability>{colorlab::drivers::Capability::camera});
  EXPECT_FALSE(instrument->identity().simulated);

  const Error e = connect_error(io, *instrument);
  EXPECT_EQ(e.cls(), ErrorClass::no_comms) << e.what();
  EXPECT_NE(std::string(e.what()).find("no camera detected"), std::string::npos) << e.what();
  EXPECT_NE(e.hint().find("USB"), std::string::npos) << e.hint();
  EXPECT_EQ(instrument->state(), colorlab::drivers::InstrumentState::disconnected);
  EXPECT_FALSE(instrument->last_problem().empty());
}

TEST(camera_factory, gphoto2_on_a_named_usb_port_that_is_absent_is_a_typed_error) {
  boost::asio::io_context io;
  auto instrument =
      colorlab::drivers::make_instrument(io.get_executor(), InstrumentConfig{"eos", "gphoto2", "usb:999,999", false, {}});
  const Error e = connect_error(io, *instrument);
  EXPECT_NE(e.cls(), ErrorClass::internal) << e.what();
  EXPECT_FALSE(e.hint().empty());
}

TEST(camera_factory, simdslr_without_its_simulator_is_no_comms) {
  boost::asio::io_context io;
  auto instrument = colorlab::drivers::make_instrument(
      io.get_executor(), InstrumentConfig{"dslr", "simdslr", "/tmp/colorlab-no-such-simulator.sock", true, {}});
  ASSERT_NE(dynamic_cast<cam::CameraInstrument*>(instrument.get()), nullptr);
  EXPECT_TRUE(instrument->identity().simulated);
  const Error e = connect_error(io, *instrument);
  EXPECT_EQ(e.cls(), ErrorClass::no_comms) << e.what();
  EXPECT_NE(e.hint().find("colorlab-sim"), std::string::npos) << e.hint();
}

TEST(camera_factory, new_kinds_are_known_and_bad_options_are_refused) {
  auto kinds = colorlab::drivers::known_instrument_kinds();
  for (const char* k : {"gphoto2", "simdslr", "genicam"}) EXPECT_NE(std::find(kinds.begin(), kinds.end(), k), kinds.end()) << k;
  boost::asio::io_context io;
  try {
    colorlab::drivers::make_instrument(io.get_executor(), InstrumentConfig{"eos", "gphoto2", "auto", false, {{"pair_wait_ms", "long"}}});
    ADD_FAILURE() << "accepted a non-numeric pair_wait_ms";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_parameter) << e.what();
  }
}
