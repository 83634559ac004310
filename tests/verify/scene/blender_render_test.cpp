// A renderer nobody here wrote renders the exported scene: a short simulated geometric-cabinet measurement
// (the chart read with the Spectrolino's noise, the floor grid with the LS-110's) goes through `colorlab scene`,
// Debian's Blender 3.4 runs the exported build_scene.py (Cycles, CPU, its own seeds), and the rendered floor
// luminance at the LS-110 grid spots must be the simulator's analytic truth within the render's own noise.
//
// Why this can agree at all: the simulator's geometric cabinet lights the floor by each emitter's form factor
// (direct light, black walls), and the exported scene has black walls, so Cycles' path tracing and the
// closed-form configuration factor describe the same physics from independent code.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <sys/wait.h>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <unistd.h>

#include "colorlab/verify/scene_export.hpp"
#include "simulated_runs.hpp"

namespace colorlab::verify {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr int kWidth = 160, kHeight = 80;  // 7.5 mm pixels over the 1200 × 600 mm floor
constexpr int kSamples = 32;

std::string read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

bool on_path(const std::string& tool) { return std::system(("command -v " + tool + " > /dev/null 2>&1").c_str()) == 0; }

// Every wait is bounded: a Blender that hangs is killed by timeout(1) and the test says so.
void run(const std::string& what, const std::string& cmd, const fs::path& log) {
  const int rc = std::system(("timeout 300 " + cmd + " > " + log.string() + " 2>&1").c_str());
  ASSERT_EQ(rc, 0) << what << " failed (exit " << rc << (WEXITSTATUS(rc) == 124 ? ", killed after 300 s" : "")
                   << "): " << cmd << "\n"
                   << read_file(log).substr(0, 4000);
}

// The first channel of an OpenEXR file, through OpenImageIO (python3-openimageio): a reader colorlab did not write.
std::vector<float> read_exr(const fs::path& exr, const fs::path& work) {
  const fs::path raw = work / (exr.stem().string() + ".f32");
  const std::string py =
      "import sys, numpy, OpenImageIO as oiio\n"
      "i = oiio.ImageInput.open(sys.argv[1])\n"
      "assert i, oiio.geterror()\n"
      "s = i.spec()\n"
      "assert (s.width, s.height) == (int(sys.argv[3]), int(sys.argv[4])), (s.width, s.height)\n"
      "assert s.format == oiio.FLOAT, s.format\n"
      "numpy.asarray(i.read_image(0, 0, 0, 1, 'float'))[:, :, 0].astype('<f4').tofile(sys.argv[2])\n";
  std::ofstream(work / "read_exr.py") << py;
  std::vector<float> px;
  [&] {
    run("reading " + exr.string(),
        "/usr/bin/python3 " + (work / "read_exr.py").string() + " " + exr.string() + " " +
            raw.string() + " " + std::to_string(kWidth) + " " + std::to_string(kHeight),
        work / "read_exr.log");
  }();
  const std::string bytes = read_file(raw);
  px.resize(bytes.size() / sizeof(float));
  std::memcpy(px.data(), bytes.data(), px.size() * sizeof(float));
  return px;
}

TEST(BlenderRender, TheExportedScenesFloorLuminanceIsTheSimulatorsWithinTheRendersNoise) {
  // CI installs blender through scripts/setup.sh: missing, this fails rather than skips.
  ASSERT_TRUE(on_path("blender")) << "blender is not installed: scripts/setup.sh installs it (Debian package blender)";
  ASSERT_TRUE(fs::exists("/usr/bin/python3")) << "python3 is missing";
  const fs::path work = fs::temp_directory_path() / ("colorlab-blender-" + std::to_string(::getpid()));
  fs::remove_all(work);
  fs::create_directories(work);

  // The short simulated measurement: D65 alone, full dimmer.
  sim::SceneConfig config;
  config.geometric_cabinet = default_cabinet();
  config.lamps_on_at_start = {sim::Lamp::d65};
  auto scene = std::make_shared<sim::Scene>(config, std::make_shared<sim::SimClock>(1.0));
  std::ofstream(work / "chart.json") << testing::chart_read_run(*scene, 21).dump();
  std::ofstream(work / "grid.json") << testing::cabinet_grid_run(*scene, {sim::Lamp::d65}, {100.0}, 22).dump();
  run("colorlab scene",
      std::string(COLORLAB_BIN_DIR) + "/colorlab scene " + (work / "chart.json").string() + " " +
          (work / "grid.json").string() + " --lamp D65 -o " + (work / "scene").string(),
      work / "scene.log");
  const json exported = json::parse(read_file(work / "scene" / "scene.json"));

  const std::string blender = "blender -b --factory-startup -noaudio -P " + (work / "scene" / "build_scene.py").string() +
                              " -- --view top --size " + std::to_string(kWidth) + "x" + std::to_string(kHeight) +
                              " --samples " + std::to_string(kSamples) + " --threads 2";
  for (int seed : {1, 2})
    run("blender, seed " + std::to_string(seed),
        blender + " --mode luminance --seed " + std::to_string(seed) + " --out " + (work / ("s" + std::to_string(seed))).string(),
        work / "blender.log");
  run("blender, bands", blender + " --mode bands --bands 450,550,650 --seed 1 --out " + (work / "bands").string(), work / "blender.log");

  const auto a = read_exr(work / "s1" / "luminance_D65.exr", work), b = read_exr(work / "s2" / "luminance_D65.exr", work);
  ASSERT_EQ(a.size(), static_cast<std::size_t>(kWidth * kHeight));
  ASSERT_EQ(b.size(), a.size());
  const double pitch = 1200.0 / kWidth;
  auto centre = [&](int i, int j) { return std::pair{(i + 0.5) * pitch, 600.0 - (j + 0.5) * pitch}; };
  // Off the chart (its board, with a pixel's margin), the floor is what the spots see.
  const double cx = default_cabinet().chart_center_x_mm, cy = default_cabinet().chart_center_y_mm;
  auto on_chart = [&](double x, double y) { return std::abs(x - cx) < 279.4 / 2 + 2 * pitch && std::abs(y - cy) < 215.9 / 2 + 2 * pitch; };

  // The renderer's own noise, from the two seeds: per pixel, the relative difference (a − b) / mean over √2. It
  // varies over the floor (the emitter's solid angle and its edges change the sampling's variance), so each spot
  // takes it from the 7 × 7 bare-floor pixels around it; a spot's value is the mean of 3 × 3 pixels in two renders,
  // 18 independent estimates.
  auto rel_diff = [&](int i, int j) {
    const std::size_t k = static_cast<std::size_t>(j * kWidth + i);
    return (a[k] - b[k]) / (0.5 * (a[k] + b[k]));
  };
  auto local_sigma = [&](int i0, int j0, int half) {
    double ss = 0;
    int n = 0;
    for (int j = std::max(j0 - half, 0); j <= std::min(j0 + half, kHeight - 1); ++j)
      for (int i = std::max(i0 - half, 0); i <= std::min(i0 + half, kWidth - 1); ++i) {
        const auto [x, y] = centre(i, j);
        if (on_chart(x, y)) continue;
        ss += std::pow(rel_diff(i, j), 2);
        ++n;
      }
    return std::sqrt(ss / n / 2.0);
  };
  const double sigma_pixel = local_sigma(kWidth / 2, kHeight / 2, kWidth);  // the whole bare floor
  // The exported level is fitted to noisy LS-110 readings: its own stated standard error scales every pixel.
  const double level_se = exported["lamps"][0]["level"]["standard_error_pct"].get<double>() / 100.0;
  std::cout << "render noise per pixel " << 100 * sigma_pixel << " % (whole floor), level SE " << 100 * level_se << " %\n";
  EXPECT_LT(sigma_pixel, 0.2) << "the render is too noisy to say anything";

  int checked = 0;
  double worst = 0;
  for (int r = 0; r < sim::floor_rows; ++r) {
    for (int c = 0; c < sim::floor_cols; ++c) {
      const auto [x, y] = sim::Scene::floor_spot_position_mm(r, c);
      if (on_chart(x, y)) continue;
      const int i = static_cast<int>(x / pitch), j = static_cast<int>((600.0 - y) / pitch);
      double rendered = 0, truth = 0;
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const std::size_t k = static_cast<std::size_t>((j + dj) * kWidth + i + di);
          rendered += 0.5 * (a[k] + b[k]) / 9;
          const auto [px, py] = centre(i + di, j + dj);
          truth += scene->lamp_floor_luminance(sim::Lamp::d65, 100.0, px, py) / 9;
        }
      const double ratio = rendered / truth;
      // 5 σ of the render at this spot (a chance of 6e-7 of a false failure per spot were the noise Gaussian)
      // plus 4 standard errors of the exported level.
      const double bound = 5 * local_sigma(i, j, 3) / std::sqrt(18.0) + 4 * level_se;
      worst = std::max(worst, std::abs(ratio - 1) / bound);
      EXPECT_NEAR(ratio, 1.0, bound) << "spot row " << r << " col " << c << ": rendered " << rendered << " cd/m², simulated " << truth;
      ++checked;
    }
  }
  std::cout << checked << " spots, worst |rendered/simulated − 1| = " << worst << " of its bound\n";
  EXPECT_GT(checked, 120);

  // Per band: the floor's band radiance is the simulator's spectral radiance of its 0.30 grey in that band.
  // Same seed as render 1 and the same floor albedo: the band image is render 1 scaled by the band's emission, so
  // only the level's standard error and float rounding separate them from the simulated truth.
  const sim::Spectrum grey{380.0, 350.0, {0.30, 0.30}};
  for (double nm : {450.0, 550.0, 650.0}) {
    std::ostringstream name;
    name << "band_" << nm << "nm.exr";
    const auto band = read_exr(work / "bands" / name.str(), work);
    ASSERT_EQ(band.size(), a.size());
    for (int r : {0, 4, 7}) {
      for (int c : {0, 3, 16, 19}) {
        const auto [x, y] = sim::Scene::floor_spot_position_mm(r, c);
        const int i = static_cast<int>(x / pitch), j = static_cast<int>((600.0 - y) / pitch);
        const auto [px, py] = centre(i, j);
        const sim::Spectrum radiance = scene->spectral_radiance(px, py, grey);  // 5 nm grid; D65 alone, warm
        const double truth = radiance.at(nm) * 10.0;
        const std::size_t k = static_cast<std::size_t>(j * kWidth + i);
        EXPECT_NEAR(band[k] / truth, 1.0, 5 * sigma_pixel + 4 * level_se) << nm << " nm at row " << r << " col " << c;
      }
    }
  }
  fs::remove_all(work);
}

}  // namespace
}  // namespace colorlab::verify
