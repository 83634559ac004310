// characterize-camera on the simulated lab (chapter 7): chart-read gives the reference, the
// simulated DSLR photographs the cabinet's chart at its seeded pose as RAW, TIFF 16/8 and JPEG, and
// the run's located chart, patch values and cross-validated errors are held to the simulator's
// ground truth (camera_truth: each patch's noiseless mean counts and the pixel spread injected there).
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <random>

#include <gtest/gtest.h>

#include "colorlab/analysis/characterization.hpp"
#include "colorlab/sim/control_channel.hpp"
#include "resume_support.hpp"

using namespace colorlab;
using namespace colorlab::testing;
using nlohmann::json;

namespace {

constexpr std::uint64_t kSeed = 5;
constexpr int kFrames = 4;

json run_to_end(const client::ApiClient& api, const std::string& campaign, const json& params) {
  auto e = api.post("/v1/executions", {{"campaign", campaign}, {"params", params}});
  auto done = wait_terminal(api, e["id"], std::chrono::seconds(240));
  EXPECT_EQ(done["status"], "finished_ok") << done.dump(2);
  return api.get("/v1/runs/" + e["run_id"].get<std::string>());
}

json control(const DaemonProcess& daemon, const json& command) {
  json endpoint = json::parse(std::ifstream(daemon.state_dir() / "colorlabd.endpoint"));
  return sim::send_control_command(endpoint.at("simulator_control").get<std::string>(), command);
}

}  // namespace

TEST(CharacterizeCamera, FitsEveryFormatWithinTheNoiseTheSimulatorInjects) {
  TempDir dir;
  auto config = write_daemon_config(dir.path(), 500, kSeed);
  // Half the 20D's sensor: the chart still spans hundreds of pixels, and four formats × 4 frames
  // render quickly on a shared CI machine.
  std::ofstream(dir / "lab.toml") << "[genicam]\nenabled = false\n[dslr]\nsize = [1752, 1168]\n";
  DaemonProcess daemon(dir / "state", config);
  auto api = api_for(daemon);

  json reference = run_to_end(api, "chart-read", json::object());
  ASSERT_EQ(reference["measurements"].size(), 140u);
  json run = run_to_end(api, "characterize-camera", {{"reference_run", reference["id"]}, {"frames", kFrames}});
  ASSERT_EQ(run["status"], "finished_ok") << run["error"].dump(2);
  const json& result = run["summary"]["script"];
  ASSERT_TRUE(result.is_object()) << run.dump(2).substr(0, 4000);

  // Every format's photograph located with confidence and passing its own neutral check.
  for (const char* format : {"raw", "tiff16", "tiff8", "jpeg"}) {
    const json& f = result["formats"][format];
    EXPECT_GE(f["confidence"].get<double>(), 0.8) << format;
    EXPECT_TRUE(f["check"]["passed"].get<bool>()) << format << ": " << f["check"].dump();
    EXPECT_TRUE(f["approaches"].contains("icc_profile")) << format;
    EXPECT_TRUE(f["approaches"].contains("adapted_mapping")) << format;
    EXPECT_EQ(f["approaches"].contains("camera_colour_space"), std::string(format) != "raw") << format;
    // An honest error is never below the fit's own.
    const json& m = f["approaches"]["adapted_mapping"];
    EXPECT_GE(m["cv"]["mean"].get<double>(), m["training"]["mean"].get<double>()) << format;
  }

  // The raw patch values against the truth of the last shot (all shots share the lamp state).
  json truth = control(daemon, {{"cmd", "camera_truth"}, {"instrument", "dslr"}});
  ASSERT_TRUE(truth.value("ok", false)) << truth.dump();
  const double black = truth["black_level"].get<double>();
  std::set<int> dusty;
  for (const auto& p : truth["dust_patches"]) dusty.insert(p.get<int>());
  std::map<std::string, std::array<double, 3>> measured;
  for (const auto& m : run["measurements"]) {
    const std::string step = m["step"];
    if (step.rfind("patch/raw/", 0) != 0) continue;
    const auto& rgb = m["data"]["rgb"];
    measured[m["data"]["id"].get<std::string>()] = {rgb[0].get<double>(), rgb[1].get<double>(), rgb[2].get<double>()};
  }
  ASSERT_EQ(measured.size(), 140u);
  // Reference colours of the chart-read run, by patch id.
  std::map<std::string, std::pair<std::array<double, 3>, std::array<double, 3>>> ref;  // id → (XYZ, Lab)
  for (const auto& m : reference["measurements"]) {
    const auto& d = m["data"];
    ref[d["id"].get<std::string>()] = {{d["XYZ"][0], d["XYZ"][1], d["XYZ"][2]}, {d["Lab"][0], d["Lab"][1], d["Lab"][2]}};
  }
  // Patch ids in index order (0..139 = A1, A2, …): the chart-read run records them in table order,
  // the camera in layout order, which is the truth's.
  std::vector<std::string> ids;
  for (const auto& m : run["measurements"]) {
    if (m["step"].get<std::string>().rfind("patch/raw/", 0) == 0) ids.push_back(m["data"]["id"]);
  }
  const auto& patches = truth["patches"];
  ASSERT_EQ(patches.size(), ids.size());

  analysis::ChartData truth_data;
  std::vector<std::array<double, 3>> sigma_mean;
  const std::size_t n = ids.size();
  truth_data.rgb.resize(static_cast<Eigen::Index>(n), 3);
  truth_data.xyz.resize(static_cast<Eigen::Index>(n), 3);
  truth_data.lab.resize(static_cast<Eigen::Index>(n), 3);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& p = patches[i];
    const auto r = static_cast<Eigen::Index>(i);
    truth_data.ids.push_back(ids[i]);
    // Pixels of one CFA colour in the sampled square (0.6 of the side): a quarter of them for R and
    // B, half for G. PRNU does not average out over frames, so no credit is taken for the frames:
    // the patch mean's spread is at most the pixel spread over √pixels.
    const double pixels = p["region"][2].get<double>() * p["region"][3].get<double>() * 0.36;
    std::array<double, 3> s{};
    for (int c = 0; c < 3; ++c) {
      const double t = p["mean"][c].get<double>() - black;
      s[static_cast<std::size_t>(c)] = p["pixel_sigma"][c].get<double>() / std::sqrt(pixels * (c == 1 ? 0.5 : 0.25));
      truth_data.rgb(r, c) = t;
      truth_data.xyz(r, c) = ref.at(ids[i]).first[static_cast<std::size_t>(c)];
      truth_data.lab(r, c) = ref.at(ids[i]).second[static_cast<std::size_t>(c)];
      if (!dusty.count(static_cast<int>(i))) {
        // 5 σ of the patch mean, plus 0.5 % for the light field's curvature across the sampled
        // square that a mean over the whole patch region and one over its centre see differently.
        EXPECT_NEAR(measured.at(ids[i])[static_cast<std::size_t>(c)], t, 5 * s[static_cast<std::size_t>(c)] + 0.005 * t)
            << ids[i] << " channel " << c;
      }
    }
    sigma_mean.push_back(s);
  }

  // The selected raw model's cross-validated ΔE00 against what the same method reaches on the
  // noiseless truth, perturbed by the patch means' noise: the measured figure must lie within the
  // largest of 20 such draws (a fixed seed; the reference's own noise is common to both sides).
  const json& selected = result["formats"]["raw"]["selected"];
  const std::string method = selected["method"];
  analysis::FitOptions fo;
  for (auto t : {analysis::FitTarget::xyz_then_lab, analysis::FitTarget::lab_direct, analysis::FitTarget::xyz_lightness_weighted}) {
    if (selected["target"] == analysis::to_string(t)) fo.target = t;
  }
  const double floor = analysis::report_method(method, truth_data, fo, analysis::CvSpec::loo()).cv.s00.mean;
  std::mt19937_64 rng(kSeed);
  std::normal_distribution<double> unit(0, 1);
  double worst = floor;
  for (int draw = 0; draw < 20; ++draw) {
    analysis::ChartData noisy = truth_data;
    for (std::size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) noisy.rgb(static_cast<Eigen::Index>(i), c) += unit(rng) * sigma_mean[i][static_cast<std::size_t>(c)];
    }
    worst = std::max(worst, analysis::report_method(method, noisy, fo, analysis::CvSpec::loo()).cv.s00.mean);
  }
  const double cv_mean = result["formats"]["raw"]["approaches"]["adapted_mapping"]["cv"]["mean"];
  std::cout << "[characterize] raw " << method << " (" << selected["target"].get<std::string>() << "): CV mean ΔE00 "
            << cv_mean << "; truth floor " << floor << ", noisy truth up to " << worst << "\n";
  for (const auto& [format, f] : result["formats"].items()) {
    for (const auto& [name, a] : f["approaches"].items()) {
      std::cout << "[characterize] " << format << " " << name << ": training mean " << a["training"]["mean"] << " p95 "
                << a["training"]["p95"] << " max " << a["training"]["max"] << "; cv mean " << a["cv"]["mean"] << " p95 "
                << a["cv"]["p95"] << " max " << a["cv"]["max"] << "\n";
    }
  }
  EXPECT_LE(cv_mean, worst);
  EXPECT_EQ(result["selected"]["model"]["method"].is_string(), true);
}
