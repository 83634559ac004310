// Bench tests on the real instruments. Each runs only when its port is named in the environment:
//   COLORLAB_HW_SPECTROLINO_PORT=/dev/serial/by-id/usb-...  COLORLAB_HW_LS110_PORT=...
//   COLORLAB_HW_DMX_PORT=...  COLORLAB_HW_RELAY=auto|/dev/hidrawN
//   ctest --test-dir build -L hardware --output-on-failure
// CI names none of them, so every test skips with the reason printed.
#include <cstdlib>

#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/enttec_dmx.hpp"
#include "colorlab/drivers/hid_relay.hpp"
#include "colorlab/drivers/hidapi_transport.hpp"
#include "colorlab/drivers/ls110.hpp"
#include "colorlab/drivers/spectrolino.hpp"
#include "run_support.hpp"

namespace colorlab::test {
namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

#define REQUIRE_ENV(var, name)       \
  const std::string var = env(name); \
  if (var.empty()) GTEST_SKIP() << name " is not set: no bench instrument to test (CI has none)"

TEST(HardwareSpectrolino, ConnectsIdentifiesAndCalibratesOnTheTile) {
  REQUIRE_ENV(port, "COLORLAB_HW_SPECTROLINO_PORT");
  boost::asio::io_context io;
  drivers::SpectrolinoOptions o;
  o.port = port;
  drivers::Spectrolino s(io.get_executor(), o);
  run(io, s.connect(), std::chrono::seconds(90));
  std::cout << "Spectrolino: " << s.identity().model << " serial " << s.identity().serial << " at " << s.baud() << " baud\n";
  EXPECT_EQ(s.baud(), 57600u);
  if (s.topology() == drivers::SpectrolinoTopology::standalone) {
    GTEST_SKIP() << "stand-alone Spectrolino: calibration needs a person to place it on the tile";
  }
  run(io, s.calibrate(), std::chrono::seconds(60));
  auto st = run(io, s.table_status());
  EXPECT_TRUE(st.online);
  run(io, s.home(), std::chrono::seconds(30));
}

TEST(HardwareLs110, MeasuresOnce) {
  REQUIRE_ENV(port, "COLORLAB_HW_LS110_PORT");
  boost::asio::io_context io;
  drivers::Ls110Options o;
  o.port = port;
  drivers::Ls110 m(io.get_executor(), o);
  run(io, m.connect());
  auto r = run(io, m.measure_luminance());
  std::cout << "LS-110: " << r.raw_reply << "\n";
  EXPECT_GE(r.luminance, 0.0);
}

TEST(HardwareDmx, FindsTheWidget) {
  REQUIRE_ENV(port, "COLORLAB_HW_DMX_PORT");
  boost::asio::io_context io;
  drivers::EnttecDmxOptions o;
  o.port = port;
  o.lamps = drivers::LampMap({{"D65", 1}}, 512, false);
  drivers::EnttecDmx d(io.get_executor(), o);
  run(io, d.connect());
  std::cout << "DMX USB Pro serial " << d.identity().serial << " firmware " << d.identity().firmware << "\n";
  EXPECT_NE(d.widget_serial(), 0u);
}

TEST(HardwareRelay, SwitchesRelayOneWithReadBack) {
  REQUIRE_ENV(where, "COLORLAB_HW_RELAY");
  boost::asio::io_context io;
  drivers::HidRelayOptions o;
  o.lamps = drivers::LampMap({{"relay1", 1}}, 8, false);
  drivers::HidRelay r(io.get_executor(), std::make_unique<drivers::HidapiTransport>(where == "auto" ? "" : where), o);
  run(io, r.connect());
  run(io, r.set_lamps({"relay1"}));
  EXPECT_EQ(r.state_mask() & 1, 1);
  run(io, r.set_lamps({}));
  EXPECT_EQ(r.state_mask() & 1, 0);
}

}  // namespace
}  // namespace colorlab::test
