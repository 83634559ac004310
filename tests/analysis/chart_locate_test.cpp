// The chart locator on charts put into photographs by ImageMagick's -distort Perspective: patch centres within
// 2 px of the truth, patch values equal to the drawn colours within noise and 8-bit rounding, orientation found,
// and a clear typed refusal for no chart, a half-covered chart and corners that do not fit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "chart_locate_support.hpp"
#include "colorlab/analysis/chart_locate.hpp"
#include "colorlab/core/error.hpp"
#include "test_support.hpp"

namespace colorlab::analysis {
namespace {

using testing::FlatChart;
using testing::Posed;
using testing::Quad4;

constexpr double kCentreBound = 2.0;  // px, the goal

#define REQUIRE_IMAGEMAGICK() \
  if (!testing::have_tool("convert")) GTEST_SKIP() << "ImageMagick's convert is not installed (apt-get install imagemagick)"

struct Case {
  const char* name;
  ChartType chart;
  Quad4 dst;  // where the flat chart image's corners go
  int rotation;
};

Quad4 rotated_rect(double cx, double cy, double w, double h, double deg, double keystone = 0) {
  const double a = deg * M_PI / 180, c = std::cos(a), s = std::sin(a);
  const double pts[4][2] = {{-w / 2 * (1 - keystone), -h / 2}, {w / 2 * (1 - keystone), -h / 2}, {w / 2, h / 2}, {-w / 2, h / 2}};
  Quad4 q{};
  for (int i = 0; i < 4; ++i)
    q[static_cast<std::size_t>(i)] = {cx + c * pts[i][0] - s * pts[i][1], cy + s * pts[i][0] + c * pts[i][1]};
  return q;
}

void expect_located(const ChartLocation& loc, const Posed& truth, const FlatChart& flat, int channels_bits, double value_bound,
                    const std::string& what) {
  const ChartLayout& L = chart_layout(loc.type);
  ASSERT_EQ(loc.patches.size(), static_cast<std::size_t>(L.size()));
  double worst = 0, worst_value = 0;
  for (int k = 0; k < L.size(); ++k) {
    const auto& p = loc.patches[static_cast<std::size_t>(k)];
    EXPECT_EQ(p.id, L.ids[static_cast<std::size_t>(k)]);
    const double d = std::hypot(p.centre.x - truth.centre[static_cast<std::size_t>(k)][0], p.centre.y - truth.centre[static_cast<std::size_t>(k)][1]);
    worst = std::max(worst, d);
    EXPECT_LE(d, kCentreBound) << what << ": patch " << p.id;
    for (int ch = 0; ch < p.channels; ++ch) {
      const double want = flat.colour[static_cast<std::size_t>(k)][static_cast<std::size_t>(ch)] / (channels_bits == 8 ? 257.0 : 1.0);
      const double got = p.value[static_cast<std::size_t>(ch)].value;
      worst_value = std::max(worst_value, std::abs(got - want));
      EXPECT_NEAR(got, want, value_bound) << what << ": patch " << p.id << " channel " << ch;
    }
  }
  for (int c = 0; c < 4; ++c)
    EXPECT_LE(std::hypot(loc.corners[static_cast<std::size_t>(c)].x - truth.corner[static_cast<std::size_t>(c)][0],
                         loc.corners[static_cast<std::size_t>(c)].y - truth.corner[static_cast<std::size_t>(c)][1]),
              kCentreBound)
        << what << ": corner " << c;
  std::printf("[ %s ] worst centre error %.2f px, worst value error %.2f, confidence %.2f (margin %.2f), %d patches seen, check %s %.2f %%\n",
              what.c_str(), worst, worst_value, loc.confidence, loc.orientation_margin, loc.patches_detected, loc.check.method.c_str(),
              loc.check.worst_disagreement * 100);
}

class ImageMagickPoses : public ::testing::TestWithParam<Case> {};

TEST_P(ImageMagickPoses, FindsEveryPatchAndItsValue) {
  REQUIRE_IMAGEMAGICK();
  const Case& c = GetParam();
  const ChartLayout& L = chart_layout(c.chart);
  const FlatChart flat = testing::draw_flat_chart(L, 7, 2.0 * 257, c.chart == ChartType::cc24 ? 90 : 60);
  const auto dir = testing::temp_dir("chart-im");
  const Posed posed = testing::pose_with_imagemagick(L, flat, dir, std::string(c.name) + ".png", c.dst, 1600, 1200, "-depth 8");
  const Photo photo = read_photo(posed.file);
  ASSERT_EQ(photo.type, SampleType::u8);
  const ChartLocation loc = locate_chart(photo.view(), c.chart);
  EXPECT_EQ(loc.rotation_deg, c.rotation);
  EXPECT_FALSE(loc.from_corners);
  EXPECT_TRUE(loc.check.passed) << loc.check.detail;
  // 8-bit: the drawn colour ± noise of the mean (σ 2 counts over hundreds of pixels) and rounding to 8 bits.
  expect_located(loc, posed, flat, 8, 1.0, c.name);
}

INSTANTIATE_TEST_SUITE_P(
    Charts, ImageMagickPoses,
    ::testing::Values(Case{"sg_square", ChartType::sg140, rotated_rect(800, 600, 1000, 740, 0), 0},
                      Case{"sg_tilted", ChartType::sg140, rotated_rect(820, 580, 1100, 800, 8, 0.18), 0},
                      Case{"sg_turned_30", ChartType::sg140, rotated_rect(800, 600, 900, 660, 30, 0.1), 0},
                      Case{"sg_upside_down", ChartType::sg140, rotated_rect(800, 600, 1000, 740, 177, 0.12), 180},
                      Case{"sg_quarter_turn", ChartType::sg140, rotated_rect(800, 600, 1000, 740, 92, 0.05), 90},
                      Case{"cc24_tilted", ChartType::cc24, rotated_rect(800, 600, 1000, 720, -6, 0.15), 0},
                      Case{"cc24_upside_down", ChartType::cc24, rotated_rect(800, 600, 900, 650, 183, 0.05), 180},
                      Case{"cc24_three_quarter", ChartType::cc24, rotated_rect(800, 600, 1000, 720, 268, 0.1), 270}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(ChartLocate, SixteenBitTiffAndJpeg) {
  REQUIRE_IMAGEMAGICK();
  const ChartLayout& L = chart_layout(ChartType::sg140);
  const FlatChart flat = testing::draw_flat_chart(L, 11, 2.0 * 257, 60);
  const auto dir = testing::temp_dir("chart-im");
  const auto dst = rotated_rect(800, 600, 1050, 780, -12, 0.15);
  {
    const Posed posed = testing::pose_with_imagemagick(L, flat, dir, "sg16.tif", dst, 1600, 1200, "-depth 16 -compress zip");
    const Photo photo = read_photo(posed.file);
    ASSERT_EQ(photo.type, SampleType::u16);
    const auto loc = locate_chart(photo.view(), ChartType::sg140);
    // 16-bit: σ 2·257 per pixel, the mean of ≥ 400 pixels has σ ≤ 26; 4σ plus the half-count of the 8-bit drawing.
    expect_located(loc, posed, flat, 16, 4 * 26 + 129, "sg 16-bit TIFF");
  }
  {
    const Posed posed = testing::pose_with_imagemagick(L, flat, dir, "sg.jpg", dst, 1600, 1200, "-depth 8 -quality 92");
    const Photo photo = read_photo(posed.file);
    const auto loc = locate_chart(photo.view(), ChartType::sg140);
    // JPEG: centres as tight; values carry the codec's chroma subsampling and quantization (a few counts).
    expect_located(loc, posed, flat, 8, 6.0, "sg JPEG q92");
  }
}

TEST(ChartLocate, NoChartIsNotFound) {
  REQUIRE_IMAGEMAGICK();
  const auto dir = testing::temp_dir("chart-im");
  const auto file = dir / "nochart.png";
  ASSERT_EQ(testing::run("convert -seed 3 -size 1600x1200 plasma:tan-grey -blur 0x2 " + file.string()), 0);
  const Photo photo = read_photo(file);
  try {
    locate_chart(photo.view(), ChartType::sg140);
    FAIL() << "a photo without a chart gave a location";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::not_found) << e.what();
    EXPECT_FALSE(e.hint().empty());
    std::printf("[ no chart ] %s\n", e.what());
  }
}

// Covers part of the flat chart with a grey card before posing it.
FlatChart cover(FlatChart f, int x0, int y0, int x1, int y1) {
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x)
      for (int ch = 0; ch < 3; ++ch) f.rgb[(static_cast<std::size_t>(y) * f.width + x) * 3 + ch] = 150 * 257;
  return f;
}

TEST(ChartLocate, CoveredChartIsRefused) {
  REQUIRE_IMAGEMAGICK();
  const ChartLayout& L = chart_layout(ChartType::sg140);
  const FlatChart flat = testing::draw_flat_chart(L, 5, 2.0 * 257, 60);
  const auto dir = testing::temp_dir("chart-im");
  const auto dst = rotated_rect(800, 600, 1000, 740, 4, 0.1);
  struct Cover {
    const char* name;
    int x0, y0, x1, y1;
  } covers[] = {{"right half", flat.width / 2, 0, flat.width, flat.height},
                {"middle block", flat.width / 3, flat.height / 3, 2 * flat.width / 3, 2 * flat.height / 3},
                {"bottom third", 0, 2 * flat.height / 3, flat.width, flat.height}};
  for (const auto& c : covers) {
    const FlatChart covered = cover(flat, c.x0, c.y0, c.x1, c.y1);
    const Posed posed = testing::pose_with_imagemagick(L, covered, dir, std::string("covered-") + std::to_string(c.x0) + ".png", dst, 1600, 1200, "-depth 8");
    const Photo photo = read_photo(posed.file);
    try {
      const auto loc = locate_chart(photo.view(), ChartType::sg140);
      ADD_FAILURE() << c.name << " covered: located with confidence " << loc.confidence << " instead of refusing";
    } catch (const Error& e) {
      EXPECT_TRUE(e.cls() == ErrorClass::needs_operator || e.cls() == ErrorClass::not_found) << e.what();
      EXPECT_FALSE(e.hint().empty());
      std::printf("[ %s covered ] %s: %s\n", c.name, std::string(to_string(e.cls())).c_str(), e.what());
    }
  }
}

TEST(ChartLocate, OperatorCorners) {
  REQUIRE_IMAGEMAGICK();
  const ChartLayout& L = chart_layout(ChartType::sg140);
  const FlatChart flat = testing::draw_flat_chart(L, 9, 2.0 * 257, 60);
  const auto dir = testing::temp_dir("chart-im");
  const Posed posed = testing::pose_with_imagemagick(L, flat, dir, "corners.png", rotated_rect(800, 600, 1000, 740, 175, 0.1), 1600, 1200, "-depth 8");
  const Photo photo = read_photo(posed.file);
  LocateOptions o;
  std::array<Point2, 4> clicked{};
  // A person clicks within a few pixels.
  const double jitter[4][2] = {{3, -2}, {-2, 3}, {2, 2}, {-3, -1}};
  for (int c = 0; c < 4; ++c)
    clicked[static_cast<std::size_t>(c)] = {posed.corner[static_cast<std::size_t>(c)][0] + jitter[c][0], posed.corner[static_cast<std::size_t>(c)][1] + jitter[c][1]};
  o.corners = clicked;
  const auto loc = locate_chart(photo.view(), ChartType::sg140, o);
  EXPECT_TRUE(loc.from_corners);
  EXPECT_EQ(loc.rotation_deg, 180);
  expect_located(loc, posed, flat, 8, 1.0, "operator corners");

  // The same corners starting at the wrong one (the chart read upside down): refused, never sampled silently.
  std::array<Point2, 4> wrong{clicked[2], clicked[3], clicked[0], clicked[1]};
  o.corners = wrong;
  try {
    const auto bad = locate_chart(photo.view(), ChartType::sg140, o);
    ADD_FAILURE() << "corners in the wrong order accepted with confidence " << bad.confidence;
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::needs_operator) << e.what();
  }
  // Corners one patch off: the repeated neutrals disagree.
  std::array<Point2, 4> shifted = clicked;
  const double px = (posed.centre[10][0] - posed.centre[0][0]), py = (posed.centre[10][1] - posed.centre[0][1]);  // one column
  for (auto& p : shifted) p.x += px, p.y += py;
  o.corners = shifted;
  EXPECT_THROW(locate_chart(photo.view(), ChartType::sg140, o), Error);
}

TEST(ChartLocate, BadInputIsTyped) {
  std::vector<std::uint8_t> px(100 * 100, 128);
  PhotoView v{px.data(), 100, 100, 1, SampleType::u8};
  try {
    locate_chart(v, ChartType::cc24);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::not_found);
  }
  PhotoView empty;
  EXPECT_THROW(locate_chart(empty, ChartType::sg140), Error);
  EXPECT_THROW(chart_type_from_string("passport"), Error);
  EXPECT_THROW(read_photo("/nonexistent/photo.tif"), Error);
}

}  // namespace
}  // namespace colorlab::analysis
