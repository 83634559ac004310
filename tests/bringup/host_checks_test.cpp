// The host listing on an injected sysfs tree and rule directories: known instruments named by their
// USB identity (instrument-protocols §3a/§3b, the udev rules' own VID:PID lines), the rules found only
// where udevd reads them.
#include <fstream>

#include <gtest/gtest.h>

#include "colorlab/bringup/host_checks.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace colorlab::test {
namespace {

namespace bu = colorlab::bringup;
namespace fs = std::filesystem;

void attr(const fs::path& dir, const std::string& name, const std::string& value) {
  fs::create_directories(dir);
  std::ofstream(dir / name) << value << "\n";
}

TEST(HostChecks, UsbDevicesFromSysfsAreNamedByTheirIdentity) {
  testing::TempDir dir;
  bu::HostPaths paths;
  paths.sysfs_usb = (dir / "usb").string();
  paths.dev_bus_usb = (dir / "dev").string();
  auto widget = dir / "usb" / "1-1";
  attr(widget, "idVendor", "0403");
  attr(widget, "idProduct", "6001");
  attr(widget, "product", "DMX USB PRO");
  attr(widget, "manufacturer", "ENTTEC");
  attr(widget, "serial", "EN123456");
  attr(widget, "busnum", "1");
  attr(widget, "devnum", "4");
  auto camera = dir / "usb" / "1-2";
  attr(camera, "idVendor", "04a9");
  attr(camera, "idProduct", "3077");
  attr(camera, "busnum", "1");
  attr(camera, "devnum", "5");
  attr(dir / "usb" / "1-1:1.0", "bInterfaceClass", "ff");  // an interface, not a device
  auto list = bu::usb_devices(paths);
  ASSERT_EQ(list.size(), 2u) << list.dump(2);
  EXPECT_EQ(list[0]["known_as"], "Enttec DMX USB Pro");
  EXPECT_EQ(list[0]["serial"], "EN123456");
  EXPECT_EQ(list[0]["usb_vid"], 0x0403);
  EXPECT_EQ(list[1]["known_as"], "Canon EOS 20D (gphoto2)");
  // The camera is opened through its /dev/bus/usb node, which does not exist here: said so.
  EXPECT_EQ(list[1]["node"]["path"], (dir / "dev" / "001" / "005").string());
  EXPECT_EQ(list[1]["node"]["access"], false);
  EXPECT_EQ(list[1]["node"]["problem"], "does not exist");
}

TEST(HostChecks, KnownDevicesNeedTheProductStringWhereThePidIsShared) {
  EXPECT_EQ(bu::known_usb_device(0x16c0, 0x05df, "USBRelay8"), "dcttech USB HID relay board");
  EXPECT_EQ(bu::known_usb_device(0x16c0, 0x05df, "some V-USB gadget"), "");
  EXPECT_NE(bu::known_usb_device(0x0403, 0x6001, "FT232R USB UART").find("serial adapter"), std::string::npos);
  EXPECT_EQ(bu::known_usb_device(0x0403, 0x6001, "DMX USB PRO"), "Enttec DMX USB Pro");
}

TEST(HostChecks, UdevRulesCountOnlyWhereUdevdReadsThem) {
  testing::TempDir dir;
  bu::HostPaths paths;
  paths.udev_rule_dirs = {(dir / "etc").string(), (dir / "lib").string()};
  auto none = bu::udev_rules_state(paths);
  EXPECT_EQ(none["installed"], false);
  EXPECT_NE(none["hint"].get<std::string>().find("70-colorlab.rules"), std::string::npos);
  attr(dir / "lib", "70-colorlab.rules", "# rules");
  auto some = bu::udev_rules_state(paths);
  EXPECT_EQ(some["installed"], true);
  ASSERT_EQ(some["found"].size(), 1u);
  EXPECT_EQ(some["found"][0], (dir / "lib" / "70-colorlab.rules").string());
}

TEST(HostChecks, AccessOfAMissingNodeSaysSoWithAHint) {
  auto a = bu::check_access("/dev/does-not-exist-colorlab");
  EXPECT_FALSE(a.readable_writable);
  EXPECT_EQ(a.problem, "does not exist");
  EXPECT_FALSE(a.hint.empty());
}

}  // namespace
}  // namespace colorlab::test
