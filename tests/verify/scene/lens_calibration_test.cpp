// The lab's lens calibration (issue 23): the simulator photographs its SG through one fixed lens — its intrinsics
// and radial distortion are the truth — at several poses; the chart locator finds each on the raw mosaic and its
// detected patch centres go into calibrate_lens (OpenCV calibrateCamera). The recovered lens must lie within its
// own stated uncertainty of the truth, and a camera pose computed with it (the export's, from the located chart's
// corners) must be closer to the simulator's camera than one computed with the nominal lens. Plus the [[lens]]
// table's parsing, refusals and the choice of a calibration by name or photograph size.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <numbers>
#include <unistd.h>

#include "colorlab/analysis/chart_layout.hpp"
#include "colorlab/analysis/chart_locate.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/sim/camera/camera_model.hpp"
#include "colorlab/verify/cabinet.hpp"
#include "colorlab/verify/lens_calibration.hpp"
#include "colorlab/verify/scene_export.hpp"
#include "located_chart_run.hpp"
#include "raw_photo_view.hpp"
#include "simulator_camera.hpp"
#include "simulated_runs.hpp"

namespace colorlab::verify {
namespace {

namespace cam = colorlab::sim::camera;
namespace ca = colorlab::analysis;
using nlohmann::json;

// Each parameter within k = 3 of its stated one-σ uncertainty: six parameters together, a calibrated σ passes
// all six with probability 0.997⁶ ≈ 98 %.
constexpr double kSigmas = 3.0;
constexpr int kWidth = 1752, kHeight = 1168;
constexpr double kPitchMm = 19.0;  // the SG's patch pitch (the chart's known geometry; the scale does not enter the intrinsics)

// The simulator's lens: a ~31 mm lens on the 22.5 mm sensor with barrel distortion, its principal point a few
// pixels off the frame's centre and fy 0.1 % longer than fx, as a real lens and sensor have them (ChartPose's
// principal_dx_px, principal_dy_px, fy_over_fx). The simulator's posed chart is seen through that pinhole with a
// focal length that keeps the chart at chart_height_fraction of the frame: fx = fraction · height · distance / chart
// height. So one lens at several poses is each pose's distance with the fraction that gives this fx.
constexpr double kF = 2450.0, kAspect = 1.001, kDx = 3.5, kDy = -2.5;
cam::LensIntrinsics true_lens() { return {kF, kF * kAspect, kWidth / 2.0 - 0.5 + kDx, kHeight / 2.0 - 0.5 + kDy, -0.09, 0.04}; }

cam::ChartPose pose(double tilt, double swing, double rot, double sx, double sy, double distance) {
  cam::ChartPose p;
  p.tilt_deg = tilt, p.swing_deg = swing, p.rotation_deg = rot, p.shift_x = sx, p.shift_y = sy, p.distance_mm = distance;
  p.k1 = true_lens().k1, p.k2 = true_lens().k2;
  p.principal_dx_px = kDx, p.principal_dy_px = kDy, p.fy_over_fx = kAspect;
  return p;
}

std::shared_ptr<sim::Scene> make_scene() {
  sim::SceneConfig sc;
  sc.seed = 4;
  sc.lamps_on_at_start = {sim::Lamp::d65};
  return std::make_shared<sim::Scene>(sc, std::make_shared<sim::SimClock>());
}

// The simulator photographs the chart at one pose through the fixed lens; the locator finds it as
// characterize-camera does (no lens given: the lens is what is being calibrated).
std::string read_text(const std::filesystem::path& p) {
  std::ifstream f(p);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// Written as a 16-bit PGM (the raw mosaic's counts as they are), for `colorlab lens calibrate`.
void write_pgm(const cam::RawFrame& f, const std::filesystem::path& path) {
  std::ofstream o(path, std::ios::binary);
  o << "P5\n"
    << f.width << " " << f.height << "\n65535\n";
  for (const auto v : f.pixels) o.put(static_cast<char>(v >> 8)).put(static_cast<char>(v & 0xff));
}

ca::ChartLocation photograph_and_locate(const std::shared_ptr<sim::Scene>& scene, const cam::ChartPose& p,
                                        const std::filesystem::path& pgm = {}, double* black = nullptr) {
  cam::CameraConfig cc;
  cc.width = kWidth, cc.height = kHeight;
  cc.pose = p;
  cc.chart_height_fraction = kF * sim::chart_height_mm / (kHeight * p.distance_mm);
  const cam::CameraModel camera(scene, cc);
  const cam::LensIntrinsics l = camera.lens(), t = true_lens();  // the simulator's own statement of its lens
  EXPECT_NEAR(l.fx, t.fx, 1e-9);
  EXPECT_NEAR(l.fy, t.fy, 1e-9);
  EXPECT_NEAR(l.cx, t.cx, 1e-9);
  EXPECT_NEAR(l.cy, t.cy, 1e-9);
  EXPECT_EQ(l.k1, t.k1);
  EXPECT_EQ(l.k2, t.k2);
  cam::CameraSettings settings;
  settings.shutter_s = 1.0 / 30;
  const cam::RawFrame frame = camera.render(settings, 1);
  if (!pgm.empty()) write_pgm(frame, pgm);
  if (black) *black = frame.black_level;
  ca::LocateOptions lo;
  for (std::size_t k = 0; k < scene->chart().patches.size(); ++k) {
    if (!lo.reference) lo.reference.emplace();
    lo.reference->luminance.push_back(scene->patch_xyz(static_cast<int>(k))[1]);
  }
  return ca::locate_chart(testing::raw_view(frame), ca::ChartType::sg140, lo);
}

// The calibration points of one photograph: each detected patch's centroid as photographed, and its centre on the
// chart's plane from the SG's layout.
CalibrationView view_of(const ca::ChartLocation& loc) {
  const auto& layout = ca::chart_layout(ca::ChartType::sg140);
  CalibrationView v;
  for (int k = 0; k < layout.size(); ++k) {
    const auto& s = loc.patches[static_cast<std::size_t>(k)];
    if (!s.detected) continue;
    v.image_px.push_back({s.observed.x, s.observed.y});
    v.chart_mm.push_back({layout.centre_x(k) * kPitchMm, layout.centre_y(k) * kPitchMm});
  }
  return v;
}

json characterize_run(const ca::ChartLocation& loc) {
  json corners = json::array();
  for (const auto& c : loc.corners) corners.push_back({c.x, c.y});
  return testing::located_chart_run(corners, loc.confidence, kWidth, kHeight, loc.reprojection_rms_px);
}

TEST(LensCalibrationSim, RecoversTheSimulatorsLensWithinItsStatedUncertainty) {
  const auto scene = make_scene();
  // Six bench poses: tilted different ways, the chart pushed towards each corner of the frame and across its
  // middle, so the distortion is seen where it is large.
  const std::vector<cam::ChartPose> poses{pose(20, 0, 0, -0.18, -0.15, 800), pose(-20, 15, 3, 0.18, -0.15, 850),
                                          pose(10, -20, -3, -0.18, 0.15, 800), pose(-15, -15, 5, 0.18, 0.15, 850),
                                          pose(0, 25, -4, 0, 0, 750), pose(25, 10, 2, 0.05, 0, 900)};
  const auto dir = std::filesystem::temp_directory_path() / ("colorlab-lens-sim-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::vector<CalibrationView> views;
  std::string photos;
  double black = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const auto pgm = dir / ("pose" + std::to_string(i) + ".pgm");
    views.push_back(view_of(photograph_and_locate(scene, poses[i], pgm, &black)));
    photos += " " + pgm.string();
  }
  LensCalibration l = calibrate_lens(views, kWidth, kHeight);

  const cam::LensIntrinsics t = true_lens();
  const double truth[6] = {t.fx, t.fy, t.cx, t.cy, t.k1, t.k2};
  const double got[6] = {l.intrinsics.fx, l.intrinsics.fy, l.intrinsics.cx, l.intrinsics.cy, l.intrinsics.k1, l.intrinsics.k2};
  const double sigma[6] = {l.sigma.fx, l.sigma.fy, l.sigma.cx, l.sigma.cy, l.sigma.k1, l.sigma.k2};
  const char* names[6] = {"fx", "fy", "cx", "cy", "k1", "k2"};
  std::printf("[ calibration ] %d photographs, %d points, RMS %.3f px\n", l.photographs, l.points, l.rms_px);
  for (int i = 0; i < 6; ++i) {
    std::printf("[ calibration ] %s = %.5g (truth %.5g, σ %.3g, off %.2f σ)\n", names[i], got[i], truth[i], sigma[i],
                std::abs(got[i] - truth[i]) / sigma[i]);
    EXPECT_GT(sigma[i], 0) << names[i];
    EXPECT_LE(std::abs(got[i] - truth[i]), kSigmas * sigma[i]) << names[i] << " = " << got[i] << ", truth " << truth[i] << ", σ " << sigma[i];
  }

  // `colorlab lens calibrate` on the same photographs (the raw mosaics as 16-bit PGM): the same calibration, to a
  // hundredth of its own σ (its chart points are in grid units rather than mm, so the solver's path differs).
  const std::string cmd = std::string(COLORLAB_BIN_DIR) + "/colorlab --json lens calibrate" + photos +
                          " --camera cam --lens lens --cfa RGGB --bits 12 --min-confidence 0.05 --black " + std::to_string(black) + " > " +
                          (dir / "out").string() + " 2> " + (dir / "err").string();
  if (std::system(cmd.c_str()) != 0) {
    ADD_FAILURE() << read_text(dir / "err");
  } else {
    std::ifstream f(dir / "out");
    const json cli = json::parse(f);
    const json mine = lens_to_json(l);
    for (const char* k : names) {
      EXPECT_NEAR(cli[k].get<double>(), mine[k].get<double>(), 0.01 * mine["sigma"][k].get<double>()) << k;
      EXPECT_NEAR(cli["sigma"][k].get<double>(), mine["sigma"][k].get<double>(), 0.01 * mine["sigma"][k].get<double>()) << k;
    }
    EXPECT_EQ(cli["points"], l.points);
    EXPECT_EQ(cli["name"], "cam / lens");
  }
  std::filesystem::remove_all(dir);

  // The stated σ is not so wide that it says nothing: a lens 2 % off in focal length lies outside the band.
  EXPECT_GT(0.02 * t.fx, kSigmas * l.sigma.fx);
  EXPECT_GT(0.02 * t.fy, kSigmas * l.sigma.fy);

  // A pose with it: a seventh photograph, located as characterize-camera locates (no lens), exported with the
  // stored calibration and with the nominal lens.
  l.camera = "simulated DSLR", l.lens = "simulated 31 mm", l.source = "calibrate_lens over 6 simulated photographs",
  l.date = "2026-11-29";
  const cam::ChartPose eval = pose(-10, 12, -2, -0.03, 0.02, 950);
  const ca::ChartLocation loc = photograph_and_locate(scene, eval);
  const std::vector<json> runs{testing::chart_read_run(*scene, 1), characterize_run(loc)};
  SceneExportOptions o;
  o.lamps = {"D65"};
  o.lenses = {l};
  const json calibrated = export_scene(default_cabinet(), runs, o)["camera"];
  const json nominal = export_scene(default_cabinet(), runs, SceneExportOptions{{"D65"}, 100.0, std::nullopt, "", {}, ""})["camera"];
  EXPECT_FALSE(calibrated["estimated"].get<bool>());
  EXPECT_EQ(calibrated["lens_calibration"]["name"], l.name());
  EXPECT_NE(calibrated["intrinsics_source"].get<std::string>().find(l.name()), std::string::npos);
  EXPECT_DOUBLE_EQ(calibrated["distortion"]["k1"].get<double>(), l.intrinsics.k1);
  EXPECT_TRUE(nominal["estimated"].get<bool>());
  EXPECT_TRUE(nominal["lens_calibration"].is_null());

  const Eigen::Vector3d want = testing::simulator_camera(eval, true_lens().fx, true_lens().fy, kWidth, kHeight, *scene).position_mm;
  const auto at = [](const json& k) -> Eigen::Vector3d {
    const auto p = k["position_m"].get<std::vector<double>>();
    return Eigen::Vector3d(p[0], p[1], p[2]) * 1000;
  };
  const double off_cal = (at(calibrated) - want).norm(), off_nom = (at(nominal) - want).norm();
  std::printf("[ pose ] camera %.1f mm from the simulator's with the calibration, %.1f mm with the nominal lens "
              "(simulator at %.1f, %.1f, %.1f mm)\n",
              off_cal, off_nom, want.x(), want.y(), want.z());
  EXPECT_LT(off_cal, off_nom);
  // The pose's σ now carries the calibration's own σ beside the corners': the simulator's camera within 4 of it on
  // each axis (the position bound of verify_scene_camera_pose_test).
  const auto sd = calibrated["pose"]["position_sigma_m"].get<std::vector<double>>();
  const auto from_lens = calibrated["pose"]["sigma_sources"]["lens_calibration"]["position_m"].get<std::vector<double>>();
  for (int i = 0; i < 3; ++i) {
    std::printf("[ pose ] axis %d: %.1f mm off, σ %.1f mm (lens calibration %.1f mm)\n", i, std::abs(at(calibrated)[i] - want[i]),
                sd[static_cast<std::size_t>(i)] * 1000, from_lens[static_cast<std::size_t>(i)] * 1000);
    EXPECT_GT(from_lens[static_cast<std::size_t>(i)], 0) << i;
    EXPECT_LE(std::abs(at(calibrated)[i] - want[i]), 4 * sd[static_cast<std::size_t>(i)] * 1000) << i;
  }
}

// --- the [[lens]] table -------------------------------------------------------------------------------------

std::string write_file(const std::string& name, const std::string& text) {
  const auto p = std::filesystem::temp_directory_path() / ("colorlab-lens-test-" + std::to_string(::getpid()) + "-" + name);
  std::ofstream(p) << text;
  return p.string();
}

LensCalibration sample() {
  LensCalibration l;
  l.camera = "Canon EOS 20D \"lab\"", l.lens = "EF 28-70mm", l.focal_length_mm = 35, l.focus = "1.2 m";
  l.width_px = 3504, l.height_px = 2336;
  l.intrinsics = {4900.5, 4901.25, 1760.125, 1150.5, -0.101, 0.05};
  l.sigma = {2.5, 2.4, 1.5, 1.25, 0.002, 0.004};
  l.rms_px = 0.21, l.photographs = 8, l.points = 1100, l.source = "colorlab lens calibrate", l.date = "2026-11-29";
  return l;
}

TEST(LensCalibrationTable, WrittenReadAndServedAlike) {
  const LensCalibration l = sample();
  const std::string file = write_file("lab.toml", "[cabinet]\nwidth_mm = 1200\n\n" + lens_to_toml(l));
  const auto back = lenses_from_file(file);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].name(), "Canon EOS 20D \"lab\" / EF 28-70mm @ 35 mm, focus 1.2 m");
  EXPECT_EQ(lens_to_json(back[0]), lens_to_json(l));
  EXPECT_EQ(lens_to_json(lens_from_json(lens_to_json(l), "test")), lens_to_json(l));
  std::filesystem::remove(file);
}

TEST(LensCalibrationTable, RefusesWhatIsNoLensWithTheLine) {
  const std::string ok = "[[lens]]\ncamera = \"A\"\nlens = \"B\"\nwidth_px = 100\nheight_px = 80\nfx = 90\nfy = 90\ncx = 49.5\ncy = 39.5\n";
  const struct {
    std::string text, words;
    int line;
  } cases[] = {
      {ok + "colour = 1\n", "unknown key colour", 10},
      {"[[lens]]\ncamera = \"A\"\nlens = \"B\"\nwidth_px = 100\nheight_px = 80\nfy = 90\ncx = 49.5\ncy = 39.5\n", "missing fx", 1},
      {ok + "sigma = { fz = 1 }\n", "sigma.fz", 10},
      {"[[lens]]\ncamera = \"A\"\nlens = \"B\"\nwidth_px = 100\nheight_px = 80\nfx = 90\nfy = 90\ncx = 149.5\ncy = 39.5\n", "principal point", 1},
      {ok + "\n" + ok, "calibrated twice", 11},
      {"[[lens]]\nlens = \"B\"\nwidth_px = 100\nheight_px = 80\nfx = 90\nfy = 90\ncx = 49.5\ncy = 39.5\n", "needs camera", 1},
  };
  for (const auto& c : cases) {
    const std::string file = write_file("bad.toml", c.text);
    try {
      lenses_from_file(file);
      ADD_FAILURE() << "accepted: " << c.text;
    } catch (const Error& e) {
      EXPECT_EQ(e.cls(), ErrorClass::bad_parameter);
      EXPECT_NE(std::string(e.what()).find(file + ":" + std::to_string(c.line) + ": lens: "), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.words), std::string::npos) << e.what();
    }
    std::filesystem::remove(file);
  }
}

TEST(LensCalibrationTable, ChosenByNameElseByThePhotographsSize) {
  LensCalibration a = sample(), b = sample(), c = sample();
  b.focal_length_mm = 50;
  c.width_px = 1752, c.height_px = 1168, c.intrinsics.cx = 870, c.intrinsics.cy = 580;
  const std::vector<LensCalibration> all{a, b, c};
  EXPECT_EQ(choose_lens(all, "", 1752, 1168)->name(), c.name());  // the only one of that size
  EXPECT_FALSE(choose_lens(all, "", 4000, 3000).has_value());     // none: nominal, said so by the export
  EXPECT_EQ(choose_lens(all, b.name(), 3504, 2336)->name(), b.name());
  EXPECT_THROW(choose_lens(all, "", 3504, 2336), Error);  // two of that size: name one
  EXPECT_THROW(choose_lens(all, "nothing", 3504, 2336), Error);
}

// `colorlab scene` from run files with `--lab`: the lab file's [[lens]] for the located photograph's size is the
// camera's lens unless --lens overrides it; `colorlab lens list --lab` lists it.
TEST(LensCalibrationCli, SceneUsesTheLabFilesCalibrationUnlessLensOverrides) {
  const auto scene = make_scene();
  const auto dir = std::filesystem::temp_directory_path() / ("colorlab-lens-cli-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  LensCalibration l = sample();
  l.width_px = kWidth, l.height_px = kHeight, l.intrinsics.cx = 875.5, l.intrinsics.cy = 583.5, l.intrinsics.fx = l.intrinsics.fy = 2450;
  std::ofstream(dir / "lab.toml") << lens_to_toml(l);
  ca::ChartLocation loc;
  const double s = 1000.0 / 262.0;  // a chart seen square-on, 1000 px across 262 mm
  loc.corners = {{{876 - 131 * s, 584 - 93 * s}, {876 + 131 * s, 584 - 93 * s}, {876 + 131 * s, 584 + 93 * s}, {876 - 131 * s, 584 + 93 * s}}};
  loc.reprojection_rms_px = 0.2;
  const std::vector<json> runs{testing::chart_read_run(*scene, 1), characterize_run(loc)};
  std::ofstream(dir / "chart.json") << runs[0].dump();
  std::ofstream(dir / "char.json") << runs[1].dump();
  const std::string base = std::string(COLORLAB_BIN_DIR) + "/colorlab --json ";
  const std::string scene_cmd = base + "scene " + (dir / "chart.json").string() + " " + (dir / "char.json").string() +
                                " --lamp D65 --lab " + (dir / "lab.toml").string() + " -o " + (dir / "out").string();
  const std::string out = " > " + (dir / "log").string() + " 2> " + (dir / "err").string();
  ASSERT_EQ(std::system((scene_cmd + out).c_str()), 0) << read_text(dir / "err");
  const json said = json::parse(read_text(dir / "log"));
  EXPECT_EQ(said["lens_calibrations"], "lab file " + (dir / "lab.toml").string());
  EXPECT_NE(said["intrinsics"].get<std::string>().find(l.name()), std::string::npos) << said.dump();
  const json written = json::parse(read_text(dir / "out" / "scene.json"));
  EXPECT_EQ(written, export_scene(default_cabinet(), runs, {{"D65"}, 100.0, std::nullopt, "", lenses_from_file((dir / "lab.toml").string()), ""}));
  EXPECT_EQ(written["camera"]["lens_calibration"]["name"], l.name());
  EXPECT_DOUBLE_EQ(written["camera"]["distortion"]["k1"].get<double>(), l.intrinsics.k1);

  ASSERT_EQ(std::system((scene_cmd + " --lens 3000,3000,870,580" + out).c_str()), 0) << read_text(dir / "err");
  const json overridden = json::parse(read_text(dir / "out" / "scene.json"))["camera"];
  EXPECT_EQ(overridden["intrinsics_source"], "lens calibration given with --lens");
  EXPECT_TRUE(overridden["lens_calibration"].is_null());
  EXPECT_DOUBLE_EQ(overridden["intrinsics_px"]["fx"].get<double>(), 3000);

  EXPECT_NE(std::system((scene_cmd + " --lens-calibration nothing" + out).c_str()), 0);
  EXPECT_NE(read_text(dir / "err").find("no lens calibration named"), std::string::npos) << read_text(dir / "err");

  ASSERT_EQ(std::system((base + "lens list --lab " + (dir / "lab.toml").string() + out).c_str()), 0) << read_text(dir / "err");
  EXPECT_EQ(json::parse(read_text(dir / "log"))["items"], json::array({lens_to_json(l)}));
  std::filesystem::remove_all(dir);
}

TEST(LensCalibrationTable, TooFewPhotographsRefused) {
  EXPECT_THROW(calibrate_lens({CalibrationView{}, CalibrationView{}}, 100, 80), Error);
}

}  // namespace
}  // namespace colorlab::verify
