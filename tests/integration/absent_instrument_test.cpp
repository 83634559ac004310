// Issue 25: an instrument that is configured but did not come up is listed as absent, with its reason,
// by GET /v1/instruments and `colorlab instruments` — not left out with the reason only in the log — and a
// campaign that needs it is refused naming it. Three ways of not coming up, each from its own cause:
//   - a second simulated lab's GigE Vision camera, whose address a first colorlab-sim already serves;
//   - an LS-110 whose device path does not exist (the adapter not plugged in);
//   - a DMX widget whose entry cannot be made into a driver (no lamp map).
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "colorlab/testing/daemon.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::testing::Process;
using colorlab::testing::RunResult;
using colorlab::testing::TempDir;
using nlohmann::json;

namespace {

json item(const json& list, const std::string& id) {
  for (const auto& i : list["items"]) {
    if (i["id"] == id) return i;
  }
  return nullptr;
}

class AbsentLab : public ::testing::Test {
 protected:
  void SetUp() override {
    // The first simulated lab takes the GigE Vision camera's address (127.0.0.1, the default).
    first_ = std::make_unique<Process>(std::vector<std::string>{colorlab::testing::bin_path("colorlab-sim"), "--control",
                                                                (dir_ / "first.sock").string()},
                                       dir_ / "first-sim.log");
    auto line = first_->read_line(std::chrono::seconds(30));
    ASSERT_TRUE(line) << "the first colorlab-sim did not announce itself (" << (dir_ / "first-sim.log") << ")";
    const json announcement = json::parse(*line);
    bool camera = false;
    for (const auto& i : announcement["instruments"]) camera = camera || i["kind"] == "genicam";
    ASSERT_TRUE(camera) << "the first colorlab-sim must hold the GigE camera's address for this test: " << *line;

    // The daemon's own simulated lab asks for the same camera (and no DSLR, so nothing else serves the
    // camera role); its configuration adds a meter on a path that is not there and an unusable widget.
    std::ofstream(dir_ / "lab.toml") << "[dslr]\nenabled = false\n";
    std::ofstream(dir_ / "colorlabd.toml")
        << "state_dir = \"" << (dir_ / "state").string() << "\"\nlisten = \"127.0.0.1:0\"\n\n"
        << "[simulator]\nenabled = true\ntime_scale = 200\nseed = 3\nconfig = \"" << (dir_ / "lab.toml").string()
        << "\"\n\n[[instrument]]\nid = \"bench-meter\"\nkind = \"ls110\"\nport = \"" << missing_port().string()
        << "\"\n\n[[instrument]]\nid = \"bench-widget\"\nkind = \"dmx\"\nport = \"/dev/colorlab/no-such-widget\"\n";
    daemon_ = std::make_unique<Process>(
        std::vector<std::string>{colorlab::testing::bin_path("colorlabd"), "--config", (dir_ / "colorlabd.toml").string()},
        dir_ / "colorlabd.log");
    auto endpoint = colorlab::testing::wait_for_endpoint(dir_ / "state", daemon_->pid(), std::chrono::seconds(60));
    socket_ = endpoint["unix_socket"];
  }

  std::filesystem::path missing_port() const { return dir_ / "no-such-ls110"; }

  RunResult cli(std::vector<std::string> args, bool as_json = true) {
    std::vector<std::string> argv{colorlab::testing::bin_path("colorlab"), "--socket", socket_};
    if (as_json) argv.push_back("--json");
    argv.insert(argv.end(), args.begin(), args.end());
    return colorlab::testing::run_command(argv, std::chrono::seconds(60));
  }

  json instruments() {
    auto r = cli({"instruments"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return json::parse(r.out.empty() ? "{\"items\":[]}" : r.out);
  }

  TempDir dir_;
  std::unique_ptr<Process> first_;
  std::unique_ptr<Process> daemon_;
  std::string socket_;
};

}  // namespace

TEST_F(AbsentLab, ApiAndCliListWhatDidNotComeUpWithItsReason) {
  json list = instruments();
  SCOPED_TRACE(list.dump(2));

  json camera = item(list, "genicam");
  ASSERT_FALSE(camera.is_null()) << "the second simulated lab's GigE camera is left out";
  EXPECT_EQ(camera["state"], "absent");
  EXPECT_EQ(camera["kind"], "genicam");
  EXPECT_TRUE(camera["simulated"]);
  EXPECT_NE(camera["reason"].get<std::string>().find("simulated lab could not start it"), std::string::npos);
  EXPECT_TRUE(camera["capabilities"].empty());

  json meter = item(list, "bench-meter");
  ASSERT_FALSE(meter.is_null());
  EXPECT_EQ(meter["state"], "absent");
  EXPECT_FALSE(meter["simulated"]);
  EXPECT_NE(meter["reason"].get<std::string>().find(missing_port().string() + " is not there"), std::string::npos);

  json widget = item(list, "bench-widget");
  ASSERT_FALSE(widget.is_null()) << "an entry that could not be made into a driver is left out";
  EXPECT_EQ(widget["state"], "absent");
  EXPECT_NE(widget["reason"].get<std::string>().find("lamps"), std::string::npos) << "the factory's own words";

  // What did come up is listed as before: the simulated lab's meter, not absent.
  json sim_meter = item(list, "ls110");
  ASSERT_FALSE(sim_meter.is_null());
  EXPECT_NE(sim_meter["state"], "absent");
  EXPECT_FALSE(sim_meter.contains("reason"));

  // The person's view: the state word and the reason on the line under it.
  auto text = cli({"instruments"}, false);
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("genicam  genicam  [absent]  (simulated)"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("absent: the simulated lab could not start it"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("bench-meter  Konica Minolta LS-110  [absent]"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("bench-widget  dmx  [absent]"), std::string::npos) << text.out;
}

TEST_F(AbsentLab, CampaignNeedingAnAbsentInstrumentIsRefusedNamingIt) {
  // frame-average needs a camera; the only one configured is the absent GigE camera.
  auto run = cli({"run", "frame-average", "-p", "frames=2"});
  EXPECT_NE(run.exit_code, 0) << run.out;
  const std::string said = run.out + run.err;
  EXPECT_NE(said.find("'genicam' is configured but absent"), std::string::npos) << said;
  EXPECT_NE(said.find("could not start it"), std::string::npos) << said;

  auto dry = cli({"run", "frame-average", "-p", "frames=2", "--dry-run"});
  EXPECT_EQ(dry.exit_code, 3) << dry.out << dry.err;
  EXPECT_NE(dry.out.find("'genicam' is configured but absent"), std::string::npos) << dry.out;

  // A meter on a path that is not there does not stand in for the simulated lab's meter, which is here.
  auto spot = cli({"run", "luminance-spot", "-p", "readings=1", "--dry-run"});
  EXPECT_EQ(spot.exit_code, 0) << spot.out << spot.err;
  json report = json::parse(spot.out.empty() ? "{}" : spot.out);
  ASSERT_TRUE(report.contains("instruments")) << spot.out;
  for (const auto& i : report["instruments"]) {
    if (i["role"] == "luminance_meter") {
      EXPECT_EQ(i["instrument"], "ls110") << report.dump(2);
    }
  }
}
