// Aravis's own command-line tools as independent clients of the simulated GigE Vision camera: Debian's
// aravis-tools-cli (arv-tool-0.8) and aravis-tools (arv-camera-test-0.8), Aravis 0.8.26. They discover it
// on loopback, read its features and pixel formats, and stream from it; every expectation is the
// simulator's truth (control channel) or docs/simulator.md, never colorlab's camera driver.
// Aravis's behaviour this relies on (AravisProject/aravis, tag 0.8.26):
//   src/arvtool.c        no command: one line per device, "<device id> (<address>)", the id ending in the
//                        serial; `control F` prints "F = value"; `features` lists each enumeration entry
//   src/arvcameratest.c  --duration streams that long, then prints "n_completed_buffers    = N"
//   src/arvgvstream.c    by default the stream thread receives through a packet socket (PF_PACKET ring);
//                        on lo it completed no frame here, for Aravis's own arv-fake-gv-camera-0.8 too,
//                        so the test streams with --no-packet-socket (its plain UDP receiver)
#include <sched.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <regex>
#include <string>

#include "../sim/serial/sim_process.hpp"
#include "client_support.hpp"
#include "colorlab/testing/process.hpp"

using colorlab::test::SimProcess;
using colorlab::testing::on_path;
using colorlab::testing::run_command;
using nlohmann::json;

namespace {

// Only the camera, at a small sensor so each frame's scene render stays cheap on a loaded machine.
const char* kLab = R"(
[ls110]
enabled = false
[spectrolino]
enabled = false
[dmx]
enabled = false
[dslr]
enabled = false
[genicam]
enabled = true
serial = "CLGVCLIENT1"
size = [352, 234]
)";

std::string tool(std::vector<std::string> argv, int seconds = 20) {
  argv[0] = colorlab::test::tool_path(argv[0]);
  auto r = run_command(argv, std::chrono::seconds(seconds));
  return r.out + r.err;
}

std::string feature(const std::string& text, const std::string& name) {
  std::smatch m;
  if (!std::regex_search(text, m, std::regex("(^|\\n)" + name + " = (\\S+)"))) return "(no " + name + " in: " + text + ")";
  return m[2];
}

}  // namespace

TEST(AravisTools, DiscoverReadAndStreamTheSimulatedCamera) {
  COLORLAB_REQUIRE_CLIENT(on_path("arv-tool-0.8"), "arv-tool-0.8 is not installed (Debian package aravis-tools-cli)");
  COLORLAB_REQUIRE_CLIENT(on_path("arv-camera-test-0.8"), "arv-camera-test-0.8 is not installed (Debian package aravis-tools)");
  COLORLAB_REQUIRE_CLIENT(on_path("ip"), "ip is not installed (Debian package iproute2)");

  // As root, the test takes a network namespace of its own with only lo, and a TMPDIR of its own for the
  // fake camera's per-address lock file, so 127.0.0.1's GVCP port is nobody else's (another simulator, a
  // colleague's test); without root it shares the machine's loopback under ctest's gigevision_loopback lock.
  struct RemoveAfterTheSimulator {
    std::filesystem::path& dir;
    ~RemoveAfterTheSimulator() {
      std::error_code ec;
      if (!dir.empty()) std::filesystem::remove_all(dir, ec);
    }
  };
  std::filesystem::path private_tmp;
  RemoveAfterTheSimulator cleanup{private_tmp};
  if (::geteuid() == 0) {
    ASSERT_EQ(::unshare(CLONE_NEWNET), 0) << "unshare(CLONE_NEWNET): " << std::strerror(errno);
    auto up = run_command({colorlab::test::tool_path("ip"), "link", "set", "lo", "up"});
    ASSERT_EQ(up.exit_code, 0) << "ip link set lo up: " << up.err;
    private_tmp = std::filesystem::temp_directory_path() / ("colorlab-arvclients-" + std::to_string(::getpid()));
    std::filesystem::create_directories(private_tmp);
    ::setenv("TMPDIR", private_tmp.c_str(), 1);
  }
  SimProcess sim(kLab);
  json truth = sim.control({{"cmd", "truth"}});
  ASSERT_TRUE(truth.contains("genicam")) << "the simulated camera did not start (GVCP port on 127.0.0.1 taken?)";
  const std::string address = truth["genicam"]["address"];
  const std::string serial = truth["genicam"]["serial"];
  ASSERT_EQ(serial, "CLGVCLIENT1");

  // Discovery: arv-tool's device list names the camera by its serial at its address.
  std::string listed = tool({"arv-tool-0.8"});
  EXPECT_TRUE(std::regex_search(listed, std::regex("-" + serial + " \\(" + std::regex_replace(address, std::regex("\\."), "\\.") + "\\)")))
      << "arv-tool-0.8 listed:\n"
      << listed;

  // Features: identity and the sensor the simulator reports.
  std::string values = tool({"arv-tool-0.8", "-a", address, "control", "DeviceID", "SensorWidth", "SensorHeight",
                             "Width", "Height"});
  EXPECT_EQ(feature(values, "DeviceID"), serial);
  EXPECT_EQ(feature(values, "SensorWidth"), std::to_string(truth["genicam"]["sensor"][0].get<int>()));
  EXPECT_EQ(feature(values, "SensorHeight"), std::to_string(truth["genicam"]["sensor"][1].get<int>()));

  // Pixel formats: docs/simulator.md adds BayerRG12 and BayerRG16 to Aravis's own list; each can be chosen.
  std::string described = tool({"arv-tool-0.8", "-a", address, "features"});
  for (const char* format : {"BayerRG12", "BayerRG16", "Mono16", "Mono8", "BayerRG8"}) {
    EXPECT_NE(described.find("EnumEntry   : '" + std::string(format) + "'"), std::string::npos)
        << format << " missing from PixelFormat:\n"
        << described;
  }
  for (const char* format : {"BayerRG12", "Mono16"}) {
    std::string set = tool({"arv-tool-0.8", "-a", address, "control", "PixelFormat=" + std::string(format), "PixelFormat"});
    EXPECT_EQ(feature(set, "PixelFormat"), format) << set;
  }

  // Streaming: a region of the sensor in BayerRG12 for two seconds; every completed buffer is one the
  // simulator filled (and a stream that completed none is a failure, however the tool exits).
  const std::uint64_t filled_before = truth["genicam"]["frames_filled"];
  auto streamed = run_command({colorlab::test::tool_path("arv-camera-test-0.8"), "-n", address, "--no-packet-socket", "--duration", "2", "-w", "64",
                               "-h", "48", "--features", "PixelFormat=BayerRG12"},
                              std::chrono::seconds(30));
  std::smatch m;
  ASSERT_TRUE(std::regex_search(streamed.out, m, std::regex(R"(n_completed_buffers\s*=\s*(\d+))"))) << streamed.out << streamed.err;
  const std::uint64_t completed = std::stoull(m[1]);
  EXPECT_GT(completed, 0u) << streamed.out;
  EXPECT_NE(streamed.out.find("image width            = 64"), std::string::npos) << streamed.out;
  EXPECT_NE(streamed.out.find("device serial number   = " + serial), std::string::npos) << streamed.out;
  truth = sim.control({{"cmd", "truth"}});
  EXPECT_GE(truth["genicam"]["frames_filled"].get<std::uint64_t>() - filled_before, completed)
      << "arv-camera-test completed more frames than the simulator filled";
}
