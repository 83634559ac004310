// `colorlab analyze locate-chart` on an ImageMagick-posed chart: JSON corners, confidence and 140 patches within
// 2 px of the truth; --corners; a photo without a chart refused with a typed error.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "chart_locate_support.hpp"
#include "colorlab/cli/analyze_command.hpp"
#include "colorlab/core/error.hpp"
#include "test_support.hpp"

namespace ca = colorlab::analysis;

namespace {

std::string run_cli(std::vector<std::string> args) {
  CLI::App app{"colorlab"};
  colorlab::cli::add_analyze_command(app);
  args.insert(args.begin(), "colorlab");
  std::vector<const char*> argv;
  for (auto& a : args) argv.push_back(a.c_str());
  ::testing::internal::CaptureStdout();
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (...) {
    ::testing::internal::GetCapturedStdout();
    throw;
  }
  return ::testing::internal::GetCapturedStdout();
}

TEST(LocateChartCli, JsonCornersAndPatches) {
  if (!ca::testing::have_tool("convert")) GTEST_SKIP() << "ImageMagick's convert is not installed (apt-get install imagemagick)";
  const auto& L = ca::chart_layout(ca::ChartType::sg140);
  const auto flat = ca::testing::draw_flat_chart(L, 3, 2.0 * 257, 60);
  const auto dir = ca::testing::temp_dir("chart-cli");
  const ca::testing::Quad4 dst{{{260, 240}, {1380, 180}, {1420, 1010}, {200, 960}}};
  const auto posed = ca::testing::pose_with_imagemagick(L, flat, dir, "sg.png", dst, 1600, 1200, "-depth 8");
  const auto j = nlohmann::json::parse(run_cli({"analyze", "locate-chart", posed.file.string(), "--chart", "sg", "--json"}));
  ASSERT_EQ(j["chart"].size(), 1u);
  EXPECT_EQ(j["chart"][0]["chart"], "sg");
  EXPECT_GE(j["chart"][0]["confidence"].get<double>(), 0.6);
  EXPECT_EQ(j["chart"][0]["check_passed"], "yes");
  ASSERT_EQ(j["corners"].size(), 4u);
  for (std::size_t c = 0; c < 4; ++c) {
    EXPECT_NEAR(j["corners"][c]["x"].get<double>(), posed.corner[c][0], 2.0);
    EXPECT_NEAR(j["corners"][c]["y"].get<double>(), posed.corner[c][1], 2.0);
  }
  ASSERT_EQ(j["patches"].size(), 140u);
  for (std::size_t k = 0; k < 140; ++k) {
    const auto& p = j["patches"][k];
    EXPECT_EQ(p["id"], L.ids[k]);
    EXPECT_NEAR(p["x"].get<double>(), posed.centre[k][0], 2.0) << L.ids[k];
    EXPECT_NEAR(p["y"].get<double>(), posed.centre[k][1], 2.0) << L.ids[k];
    EXPECT_NEAR(p["G"].get<double>(), flat.colour[k][1] / 257.0, 1.0) << L.ids[k];
  }
  // The operator's corners (rounded to whole pixels, as a person clicks them).
  std::string corners;
  for (const auto& c : posed.corner) corners += (corners.empty() ? "" : ",") + std::to_string(std::lround(c[0])) + "," + std::to_string(std::lround(c[1]));
  const std::string csv = run_cli({"analyze", "locate-chart", posed.file.string(), "--corners", corners});
  EXPECT_NE(csv.find("# patches"), std::string::npos) << csv;
  EXPECT_NE(csv.find("sg,"), std::string::npos) << csv;
  EXPECT_THROW(run_cli({"analyze", "locate-chart", posed.file.string(), "--corners", "1,2,3"}), colorlab::Error);
}

TEST(LocateChartCli, NoChartIsATypedRefusal) {
  if (!ca::testing::have_tool("convert")) GTEST_SKIP() << "ImageMagick's convert is not installed (apt-get install imagemagick)";
  const auto dir = ca::testing::temp_dir("chart-cli");
  const auto file = dir / "grey.png";
  ASSERT_EQ(ca::testing::run("convert -size 800x600 gradient:gray20-gray80 " + file.string()), 0);
  try {
    run_cli({"analyze", "locate-chart", file.string(), "--chart", "cc24"});
    FAIL() << "no refusal";
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), colorlab::ErrorClass::not_found) << e.what();
    EXPECT_NE(e.hint().find("--corners"), std::string::npos);
  }
}

}  // namespace
