// lab.analysis.calibrate_lens (the lens-calibration campaign's fit) in process: the SG's patch centres projected by the
// test's own ideal pinhole (no distortion) at four poses must give back that pinhole, with a [[lens]] table; bad
// arguments are refused naming what is wrong.
#include <cmath>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "colorlab/analysis/chart_layout.hpp"
#include "colorlab/campaigns/lens_calibration.hpp"
#include "colorlab/core/error.hpp"

using namespace colorlab;
using nlohmann::json;

namespace {

constexpr int kWidth = 1600, kHeight = 1200;
constexpr double kF = 2000, kCx = 812.5, kCy = 590.25;

// The SG's patch centres (grid units) turned by tilt about x then swing about y, `distance` grid units away.
json photograph(double tilt_deg, double swing_deg, double distance, double dx = 0, double dy = 0) {
  const auto& layout = analysis::chart_layout(analysis::ChartType::sg140);
  const double a = tilt_deg * std::numbers::pi / 180, b = swing_deg * std::numbers::pi / 180;
  json observed = json::array();
  for (int k = 0; k < layout.size(); ++k) {
    const double X = layout.centre_x(k) - layout.grid_width() / 2, Y = layout.centre_y(k) - layout.grid_height() / 2;
    // R = Rx(a) · Ry(b) applied to (X, Y, 0).
    const double x1 = std::cos(b) * X, z1 = -std::sin(b) * X;
    const double y2 = std::cos(a) * Y - std::sin(a) * z1, z2 = std::sin(a) * Y + std::cos(a) * z1;
    const double z = z2 + distance;
    observed.push_back({{"id", layout.ids[static_cast<std::size_t>(k)]}, {"x", kCx + kF * (x1 + dx) / z}, {"y", kCy + kF * (y2 + dy) / z}});
  }
  return {{"chart", "sg"}, {"width", kWidth}, {"height", kHeight}, {"observed_px", observed}};
}

json four_poses() {
  return json::array({photograph(20, 0, 40, -3, -2), photograph(-15, 20, 45, 3, -2), photograph(10, -25, 42, -3, 2),
                      photograph(-20, -10, 38, 3, 2)});
}

const json kWho = {{"camera", "bench camera"}, {"lens", "bench lens"}, {"date", "2026-11-29"}, {"by", "test"}};

ErrorClass class_of(const json& photographs, const json& options) {
  try {
    campaigns::calibrate_lens(photographs, options);
  } catch (const Error& e) {
    return e.cls();
  }
  return ErrorClass::internal;  // accepted: no class to compare
}

}  // namespace

TEST(CalibrateLensCall, RecoversTheTestsPinholeAndWritesTheLensTable) {
  const json l = campaigns::calibrate_lens(four_poses(), kWho);
  EXPECT_NEAR(l["fx"].get<double>(), kF, 1e-3 * kF);
  EXPECT_NEAR(l["fy"].get<double>(), kF, 1e-3 * kF);
  EXPECT_NEAR(l["cx"].get<double>(), kCx, 0.5);
  EXPECT_NEAR(l["cy"].get<double>(), kCy, 0.5);
  EXPECT_NEAR(l["k1"].get<double>(), 0, 1e-3);
  EXPECT_EQ(l["photographs"], 4);
  EXPECT_EQ(l["points"], 4 * 140);
  EXPECT_EQ(l["name"], "bench camera / bench lens");
  EXPECT_EQ(l["source"], "test: OpenCV calibrateCamera over 4 photographs of the ColorChecker SG (detected patch centres)");
  const std::string toml = l["toml"];
  EXPECT_EQ(toml.rfind("[[lens]]\ncamera = \"bench camera\"\nlens = \"bench lens\"\n", 0), 0u) << toml;
  EXPECT_NE(toml.find("width_px = 1600\nheight_px = 1200\n"), std::string::npos) << toml;
}

TEST(CalibrateLensCall, UndetectedPatchesAreLeftOutAndBadArgumentsRefused) {
  json poses = four_poses();
  poses[0]["observed_px"].erase(poses[0]["observed_px"].begin(), poses[0]["observed_px"].begin() + 30);  // not detected
  EXPECT_EQ(campaigns::calibrate_lens(poses, kWho)["points"], 4 * 140 - 30);

  json two = json::array({poses[0], poses[1]});
  EXPECT_EQ(class_of(two, kWho), ErrorClass::bad_parameter);  // fewer than 3 photographs
  json unknown = four_poses();
  unknown[2]["observed_px"][0]["id"] = "Z99";
  EXPECT_EQ(class_of(unknown, kWho), ErrorClass::script_error);  // not an SG patch
  json other_size = four_poses();
  other_size[1]["width"] = 800;
  EXPECT_EQ(class_of(other_size, kWho), ErrorClass::bad_parameter);  // one calibration, one size
  json nameless = kWho;
  nameless.erase("lens");
  EXPECT_EQ(class_of(four_poses(), nameless), ErrorClass::script_error);
  EXPECT_EQ(class_of(json::object(), kWho), ErrorClass::script_error);
  json garbled = four_poses();
  garbled[3]["observed_px"][5] = json::array({1, 2});
  EXPECT_EQ(class_of(garbled, kWho), ErrorClass::script_error);
}
