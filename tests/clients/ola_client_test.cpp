// The Open Lighting Architecture as an independent client of the simulated DMX USB Pro: Debian's `ola`
// 0.10.9 (OpenLightingProject/ola tag 0.10.9), its olad with only the usbserial plugin, finds the widget
// through a device folder holding a link to the simulator's pty, and its command-line clients drive the
// cabinet. Every expectation is the simulator's truth (control channel) or a value a genuine widget
// would give (docs/simulator.md; Enttec API 1.44), never colorlab's decoding. olad runs in a network
// namespace of its own holding only lo, so it reaches nothing but the pty, and its RPC port (9010, which
// OLA's clients cannot change) is free whatever else runs; the clients join that namespace with nsenter.
// OLA's behaviour this relies on:
//   plugins/usbpro/UsbSerialPlugin.cpp       device_dir / device_prefix pick the ports to probe
//   plugins/usbpro/UsbProWidgetDetector.cpp  labels 77, 78, 10, 3, 14; serial and firmware from the replies
//   plugins/usbpro/UsbProDevice.cpp          the device name "..., Serial #: %08d, firmware MAJOR.MINOR"
//   plugins/usbpro/UsbProDevice.h            an output port sends at most 5 frames back to back, then
//                                            pro_fps_limit (190) per second, and drops (never resends) the rest
//   common/io/Serial.cpp                     a UUCP lock file /var/lock/LCK..NAME per port it opens
//   olad/Olad.cpp                            olad refuses to run as root
#include <grp.h>
#include <pwd.h>
#include <signal.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>

#include "../sim/serial/sim_process.hpp"
#include "client_support.hpp"
#include "colorlab/testing/process.hpp"

namespace fs = std::filesystem;
using colorlab::test::SimProcess;
using colorlab::test::truth_slots;
using colorlab::test::wait_for;
using colorlab::testing::on_path;
using colorlab::testing::Process;
using colorlab::testing::run_command;
using nlohmann::json;

namespace {

const char* kLab = R"(
[dmx]
serial = 12345678
[ls110]
enabled = false
[spectrolino]
enabled = false
[dslr]
enabled = false
)";

// Every plugin Debian's olad 0.10.9 loads, but usbserial, is switched off, so olad opens no network socket
// but its RPC port and touches no device but the pty; the test checks that only the widget shows up.
const char* kOtherPlugins[] = {"artnet", "dummy", "e131", "espnet", "ftdidmx", "gpio", "karate", "kinet",
                               "milinst", "opendmx", "openpixelcontrol", "osc", "pathport", "renard",
                               "sandnet", "shownet", "spi", "stageprofi", "uartdmx", "usbdmx"};

// The client run inside olad's network namespace, with a bound on its time.
colorlab::testing::RunResult in_netns(const std::string& netns, std::vector<std::string> argv) {
  argv.insert(argv.begin(), {colorlab::test::tool_path("nsenter"), netns, "--"});
  return run_command(argv, std::chrono::seconds(10));
}

std::string netns_of(const std::string& pid) {
  std::error_code ec;
  return fs::read_symlink("/proc/" + pid + "/ns/net", ec).string();
}

}  // namespace

TEST(OlaClient, DetectsTheSimulatedWidgetAndDrivesTheCabinet) {
  COLORLAB_REQUIRE_CLIENT(::geteuid() == 0, "needs root to hand the pty to olad's own user (olad refuses root)");
  for (const char* tool : {"olad", "ola_dev_info", "ola_patch", "ola_set_dmx", "ola_streaming_client", "ola_usbpro"}) {
    COLORLAB_REQUIRE_CLIENT(on_path(tool), std::string(tool) + " is not installed (Debian package ola)");
  }
  for (const char* tool : {"setpriv", "unshare", "nsenter"}) {
    COLORLAB_REQUIRE_CLIENT(on_path(tool), std::string(tool) + " is not installed (Debian package util-linux)");
  }
  COLORLAB_REQUIRE_CLIENT(on_path("ip"), "ip is not installed (Debian package iproute2)");
  const passwd* user = ::getpwnam("olad");
  const group* dialout = ::getgrnam("dialout");
  COLORLAB_REQUIRE_CLIENT(user && dialout, "no user olad or group dialout (Debian's ola package creates olad)");
  const uid_t olad_uid = user->pw_uid;
  const gid_t olad_gid = user->pw_gid;
  const gid_t dialout_gid = dialout->gr_gid;

  SimProcess sim(kLab);
  const std::string pty = sim.port("dmx");
  // A pty is root's (mode 0600 or 0620): olad could not read it. A udev rule gives a real widget's ttyUSB
  // to group dialout, mode 0660, and Debian's olad user is in dialout; the test does the same by hand.
  ASSERT_EQ(::chown(pty.c_str(), static_cast<uid_t>(-1), dialout_gid), 0) << pty;
  ASSERT_EQ(::chmod(pty.c_str(), 0660), 0) << pty;

  const fs::path config = sim.dir() / "ola";
  const fs::path devices = sim.dir() / "dev";
  fs::create_directories(config);
  fs::create_directories(devices);
  const std::string link_name = "ttyUSB-colorlab-" + std::to_string(::getpid());
  fs::create_symlink(pty, devices / link_name);
  for (const char* plugin : kOtherPlugins) std::ofstream(config / ("ola-" + std::string(plugin) + ".conf")) << "enabled = false\n";
  std::ofstream(config / "ola-usbserial.conf") << "enabled = true\ndevice_dir = " << devices.string()
                                               << "\ndevice_prefix = ttyUSB\npro_fps_limit = 190\n";
  ASSERT_EQ(::chown(config.c_str(), olad_uid, olad_gid), 0);
  for (const auto& f : fs::directory_iterator(config)) ASSERT_EQ(::chown(f.path().c_str(), olad_uid, olad_gid), 0);

  const fs::path log = sim.dir() / "olad.log";
  Process olad({colorlab::test::tool_path("unshare"), "--net", "--", "sh", "-c",
                "ip link set lo up && exec setpriv --reuid=olad --regid=" + std::to_string(olad_gid) +
                    " --init-groups olad -c '" + config.string() + "' --no-http --no-register-with-dns-sd -l 3"},
               log);
  struct StopOlad {  // SIGTERM, so olad releases the widget and removes its UUCP lock file
    Process& p;
    std::string lock;
    ~StopOlad() {
      p.signal(SIGTERM);
      p.wait(std::chrono::seconds(10));
      std::error_code ec;
      fs::remove(lock, ec);
    }
  } stop{olad, "/var/lock/LCK.." + link_name};

  // unshare has moved olad out of our namespace before any client may follow it there.
  const std::string pid = std::to_string(olad.pid());
  std::string seen;
  ASSERT_TRUE(wait_for(
      [&](std::string& s) {
        s = netns_of(pid);
        return !s.empty() && s != netns_of("self");
      },
      std::chrono::seconds(10), seen))
      << "olad's process never entered a network namespace of its own (see " << log << ")";
  const std::string netns = "--net=/proc/" + pid + "/ns/net";
  auto ola = [&](std::vector<std::string> argv) {
    auto r = in_netns(netns, std::move(argv));
    return r.out + r.err;
  };

  // Detection: olad probes the port at start-up; a genuine widget is found in well under a second.
  std::string devices_seen;
  ASSERT_TRUE(wait_for(
      [&](std::string& seen) {
        seen = ola({"ola_dev_info"});
        return seen.find("Enttec Usb Pro Device") != std::string::npos;
      },
      std::chrono::seconds(30), devices_seen))
      << "olad found no DMX USB Pro on " << pty << "; ola_dev_info printed:\n"
      << devices_seen << "\n(see " << log << ")";
  std::smatch m;
  ASSERT_TRUE(std::regex_search(devices_seen, m, std::regex(R"(Device (\d+): Enttec Usb Pro Device, Serial #: (\d+), firmware (\d+\.\d+))")))
      << devices_seen;
  const std::string device = m[1];
  EXPECT_EQ(m[2], "12345678") << "the serial the lab configured";
  EXPECT_EQ(m[3], "1.44") << "docs/simulator.md: DMX firmware 1.44 (issue 25: OLA saw 1.68)";
  EXPECT_EQ(std::regex_search(devices_seen, std::regex(R"(Device \d+: (?!Enttec Usb Pro Device))")), false)
      << "only the widget: every other plugin is off\n"
      << devices_seen;

  // Parameters: a live label 3 request through OLA, then a label 4 write checked at the widget.
  std::string params = ola({"ola_usbpro", "-d", device, "-p", "0", "-g"});
  EXPECT_NE(params.find("Firmware: 1.44"), std::string::npos) << params;
  EXPECT_NE(params.find("Break Time: 96"), std::string::npos) << "9 units of 10.67 us\n"
                                                              << params;
  EXPECT_NE(params.find("Rate: 40"), std::string::npos) << params;
  ola({"ola_usbpro", "-d", device, "-p", "0", "-b", "20", "-m", "4", "-r", "30"});
  EXPECT_TRUE(wait_for(
      [&](std::string& s) {
        auto p = sim.control({{"cmd", "truth"}})["dmx"]["parameters"];
        s = p.dump();
        return p == json{{"break_time", 20}, {"mab_time", 4}, {"output_rate", 30}};
      },
      std::chrono::seconds(10), seen))
      << "the widget's parameters after ola_usbpro -b 20 -m 4 -r 30: " << seen;

  // One frame with ola_set_dmx: TL84 (channel 2) full, dimmer (channel 6) at 128.
  auto patched = in_netns(netns, {"ola_patch", "-d", device, "-p", "0", "-u", "1"});
  ASSERT_EQ(patched.exit_code, 0) << patched.out << patched.err;
  ola({"ola_set_dmx", "-u", "1", "-d", "0,255,0,0,0,128"});
  json truth;
  EXPECT_TRUE(wait_for(
      [&](std::string& s) {
        truth = sim.control({{"cmd", "truth"}});
        s = truth.dump();
        return truth_slots(truth, 6) == std::vector<int>{0, 255, 0, 0, 0, 128};
      },
      std::chrono::seconds(10), seen))
      << "the widget never received ola_set_dmx's frame; truth: " << seen << "\n(see " << log << ")";
  EXPECT_EQ(truth["lamps_on"], json::array({"TL84"}));
  EXPECT_NEAR(truth["dimmer"].get<double>(), 128 * 100.0 / 255, 1e-9) << "dimmer 0..255 -> 0..100 %";
  EXPECT_EQ(truth["dmx"]["slot_count"], 6) << "OLA sends the slots it was given";

  // A stream of frames with ola_streaming_client: four, within OLA's burst of five, so none is dropped. The
  // client reads them from a FIFO the test holds open until the widget has the last: olad's EPoller runs a
  // connection's close handler on hang-up without reading what is still buffered (common/io/EPoller.cpp,
  // CheckDescriptor), so a client that sends and exits at once (`printf … | ola_streaming_client`) loses its frames.
  const std::uint64_t packets_before = truth["dmx"]["packets"];
  const fs::path fifo = sim.dir() / "stream.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path stream_log = sim.dir() / "ola_streaming_client.log";
  Process streamer({colorlab::test::tool_path("nsenter"), netns, "--", "sh", "-c", "exec ola_streaming_client -u 1 < '" + fifo.string() + "'"},
                   stream_log);
  int fd = -1;
  ASSERT_TRUE(wait_for(  // a FIFO opens for writing only once its reader has it open
      [&](std::string& s) {
        fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
        s = fd < 0 ? std::strerror(errno) : "open";
        return fd >= 0;
      },
      std::chrono::seconds(10), seen))
      << "ola_streaming_client never opened its input: " << seen << " (see " << stream_log << ")";
  const std::string frames = "255,0,0,0,0,10\n255,0,0,0,0,80\n0,0,255,0,255,160\n255,0,0,255,0,255\n";
  ASSERT_EQ(::write(fd, frames.data(), frames.size()), static_cast<ssize_t>(frames.size()));
  EXPECT_TRUE(wait_for(
      [&](std::string& s) {
        truth = sim.control({{"cmd", "truth"}});
        s = truth.dump();
        return truth_slots(truth, 6) == std::vector<int>{255, 0, 0, 255, 0, 255};
      },
      std::chrono::seconds(10), seen))
      << "the widget never received the streamed frames' last; truth: " << seen;
  ::close(fd);
  EXPECT_EQ(streamer.wait(std::chrono::seconds(10)), 0) << "ola_streaming_client ends at the end of its input";
  EXPECT_EQ(truth["lamps_on"], json::array({"D65", "A"}));
  EXPECT_NEAR(truth["dimmer"].get<double>(), 100.0, 1e-9);
  EXPECT_EQ(truth["dmx"]["packets"].get<std::uint64_t>() - packets_before, 4u) << "one label 6 packet per frame";
  EXPECT_EQ(truth["dmx"]["bad_frames"], 0);
  EXPECT_EQ(truth["dmx"]["rejected_requests"], 0);
}
