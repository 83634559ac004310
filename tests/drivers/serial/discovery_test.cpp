// Discovery: rules that match USB-serial adapters by VID/PID/serial, explicit port overrides, the
// built-in DMX USB Pro match, come-and-go events, and the no-USB path of this machine.
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/discovery.hpp"
#include "colorlab/drivers/discovery_monitor.hpp"
#include "colorlab/sim/pty.hpp"
#include "run_support.hpp"

namespace colorlab::test {
namespace {

using drivers::Discovery;
using drivers::DiscoveryRule;
using drivers::SerialPortInfo;

SerialPortInfo usb_port(std::string path, int vid, int pid, std::string serial, std::string product) {
  SerialPortInfo p;
  p.path = std::move(path);
  p.transport = "usb";
  p.usb_vid = vid;
  p.usb_pid = pid;
  p.usb_serial = std::move(serial);
  p.usb_product = std::move(product);
  return p;
}

struct FakeBus {
  std::vector<SerialPortInfo> ports;
  std::vector<drivers::HidDeviceInfo> relays;
  Discovery::Sources sources() {
    Discovery::Sources s;
    s.serial_ports = [this] { return ports; };
    s.relay_boards = [this] { return relays; };
    s.by_id_dir = "/nonexistent-by-id";
    return s;
  }
};

TEST(DiscoveryTest, RulesMatchAdaptersByUsbSerialWhateverTheirTtyName) {
  FakeBus bus;
  // Two identical Prolific adapters: only the USB serial tells them apart.
  bus.ports = {usb_port("/dev/ttyUSB1", 0x067B, 0x2303, "PL-LS110", "USB-Serial Controller"),
               usb_port("/dev/ttyUSB0", 0x067B, 0x2303, "PL-SPECTRO", "USB-Serial Controller"),
               usb_port("/dev/ttyUSB2", 0x0403, 0x6001, "EN123456", "DMX USB PRO")};
  DiscoveryRule spectro{"spectro", "spectrolino", "", 0x067B, 0x2303, "PL-SPECTRO"};
  DiscoveryRule meter{"meter", "ls110", "", 0x067B, 0x2303, "PL-LS110"};
  Discovery d({spectro, meter}, bus.sources());
  auto found = d.scan();
  ASSERT_EQ(found.size(), 3u);
  EXPECT_EQ(found[0].id, "spectro");
  EXPECT_EQ(found[0].port, "/dev/ttyUSB0");
  EXPECT_EQ(found[1].id, "meter");
  EXPECT_EQ(found[1].port, "/dev/ttyUSB1");
  EXPECT_EQ(found[2].kind, "dmx") << "the DMX USB Pro is recognised without a rule";
  EXPECT_EQ(found[2].id, "dmx-EN123456");
  // Replugged in the other order: same ids, new paths.
  bus.ports[0].path = "/dev/ttyUSB0";
  bus.ports[1].path = "/dev/ttyUSB1";
  found = d.scan();
  EXPECT_EQ(found[0].port, "/dev/ttyUSB1");
  EXPECT_EQ(found[1].port, "/dev/ttyUSB0");
}

TEST(DiscoveryTest, ComeAndGoAreReportedToSubscribers) {
  FakeBus bus;
  Discovery d({DiscoveryRule{"spectro", "spectrolino", "", std::nullopt, std::nullopt, "PL-SPECTRO"}}, bus.sources());
  std::vector<std::string> events;
  int token = d.subscribe([&](const drivers::DiscoveryChange& c) { events.push_back((c.added ? "+" : "-") + c.instrument.id); });
  EXPECT_TRUE(d.poll().empty()) << "nothing plugged in";
  bus.ports = {usb_port("/dev/ttyUSB0", 0x067B, 0x2303, "PL-SPECTRO", "x")};
  bus.relays = {drivers::HidDeviceInfo{"/dev/hidraw3", 0x16C0, 0x05DF, "www.dcttech.com", "USBRelay4", ""}};
  d.poll();
  EXPECT_EQ(events, (std::vector<std::string>{"+spectro", "+hidrelay-hidraw3"}));
  EXPECT_TRUE(d.poll().empty()) << "no change, no events";
  bus.ports.clear();
  d.poll();
  EXPECT_EQ(events.back(), "-spectro");
  d.unsubscribe(token);
  bus.relays.clear();
  d.poll();
  EXPECT_EQ(events.size(), 3u);
}

TEST(DiscoveryTest, ExplicitPortOverrideWorksForPtys) {
  sim::Pty pty;
  FakeBus bus;  // outlives d: its sources capture the bus (a temporary's were read after its end, ASan)
  Discovery d({DiscoveryRule{"sim-spectro", "spectrolino", pty.slave_path(), std::nullopt, std::nullopt, ""},
               DiscoveryRule{"gone", "ls110", "/dev/does-not-exist", std::nullopt, std::nullopt, ""}},
              bus.sources());
  auto found = d.scan();
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].id, "sim-spectro");
  EXPECT_EQ(found[0].port, pty.slave_path());
}

TEST(DiscoveryTest, RulesWithoutAnyMatchAreRefused) {
  EXPECT_THROW(Discovery({DiscoveryRule{"x", "ls110", "", std::nullopt, std::nullopt, ""}}, FakeBus{}.sources()), Error);
  EXPECT_THROW(Discovery({DiscoveryRule{"", "ls110", "/dev/ttyS0", std::nullopt, std::nullopt, ""}}, FakeBus{}.sources()), Error);
}

TEST(DiscoveryTest, RealEnumerationOnThisMachineNeverThrows) {
  // CI has no USB: libserialport and hidapi must report nothing (or native ports), not fail.
  Discovery d({});
  std::vector<drivers::DiscoveredInstrument> found;
  EXPECT_NO_THROW(found = d.scan());
  for (const auto& f : found) EXPECT_FALSE(f.kind.empty());
}

TEST(DiscoveryMonitorTest, FallsBackToPeriodicScanWithoutUsbAndReportsArrivals) {
  boost::asio::io_context io;
  FakeBus bus;
  Discovery d({DiscoveryRule{"spectro", "spectrolino", "", std::nullopt, std::nullopt, "PL-SPECTRO"}}, bus.sources());
  drivers::DiscoveryMonitor m(io.get_executor(), d, std::chrono::milliseconds(5), 2);
  if (!drivers::UsbHotplug::unavailable_reason().empty()) {
    EXPECT_FALSE(m.hotplug_active());
    EXPECT_NE(m.hotplug_status().find("periodic"), std::string::npos) << m.hotplug_status();
  }
  int added = 0;
  d.subscribe([&](const drivers::DiscoveryChange& c) { added += c.added ? 1 : 0; });
  m.start();
  settle(io, std::chrono::milliseconds(30));
  EXPECT_EQ(added, 0);
  bus.ports = {usb_port("/dev/ttyUSB0", 0x067B, 0x2303, "PL-SPECTRO", "x")};
  // Wait for the re-scan by its effect, not by a time threshold (the machine may be loaded).
  for (int i = 0; i < 500 && added == 0; ++i) settle(io, std::chrono::milliseconds(10));
  EXPECT_EQ(added, 1);
  EXPECT_GE(m.scans(), 2);
  m.stop();
  settle(io, std::chrono::milliseconds(10));
}

}  // namespace
}  // namespace colorlab::test
