// The pieces of the comparison on inputs with an answer on paper: the coverage arithmetic, the Mahalanobis verdict,
// the scale reported, and typed errors for bad inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>

#include "colorlab/core/error.hpp"
#include "colorlab/verify/compare/stored.hpp"
#include "colorlab/verify/compare/stored_request.hpp"
#include "colorlab/verify/compare/uncertainty.hpp"
#include "colorlab/verify/compare/verification.hpp"

namespace colorlab::verify {
namespace {

TEST(VerifyUncertainty, CoverageOfKEquals2) {
  EXPECT_NEAR(coverage_probability(2), 0.9545, 1e-4);
  EXPECT_NEAR(chi_square_quantile(0.9545, 1), 4.0, 1e-3);                // k² in one dimension
  EXPECT_NEAR(chi_square_quantile(0.95, 3), 7.8147, 1e-3);               // table value
  EXPECT_NEAR(chi_square_quantile(0.95, 2), -2 * std::log(0.05), 1e-6);  // exponential in two dimensions
}

TEST(VerifyUncertainty, VerdictInOneDimensionIsKTimesSigma) {
  Eigen::MatrixXd cov(1, 1);
  cov(0, 0) = 0.25;  // σ = 0.5
  Eigen::VectorXd d(1);
  d[0] = 0.99;
  EXPECT_FALSE(judge(d, cov).differs);
  d[0] = 1.01;
  EXPECT_TRUE(judge(d, cov).differs);
  EXPECT_NEAR(judge(d, cov).expanded_along, 1.0, 1e-9);
}

TEST(VerifyUncertainty, EmptyBudgetIsATypedError) {
  Eigen::VectorXd d = Eigen::VectorXd::Ones(3);
  try {
    judge(d, Eigen::MatrixXd::Zero(3, 3));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_data);
    EXPECT_FALSE(e.hint().empty());
  }
}

Rendering flat_xyz(float y) {
  Rendering r;
  r.width = 20;
  r.height = 10;
  r.encoding = Encoding::xyz;
  r.pixels.assign(20 * 10 * 3, y);
  return r;
}

MeasuredScene two_spots(double a, double b) {
  MeasuredScene m;
  for (int i = 0; i < 2; ++i) {
    SpotMeasurement s;
    s.row = 0;
    s.col = i;
    s.luminance_cd_m2 = i ? b : a;
    s.reading_sd = 0.01 * s.luminance_cd_m2;
    s.readings = 1;
    s.rendering_region = {2 + 10 * i, 2, 4, 4};
    m.spots.push_back(s);
  }
  return m;
}

TEST(VerifyCompare, SaysWhichScaleItUsed) {
  const auto r = flat_xyz(50);
  CompareOptions given;
  given.scale = 2.0;  // renderer unit -> cd/m²: the spots read 100
  auto v = compare(r, two_spots(100, 100), given);
  ASSERT_EQ(v.scales.size(), 1u);
  EXPECT_EQ(v.scales[0].how, "given");
  EXPECT_FALSE(v.differs());
  // A uniformly 10 % bright rendering is seen with the scale given, not with one fitted.
  v = compare(r, two_spots(100 / 1.1, 100 / 1.1), given);
  EXPECT_TRUE(v.differs());
  v = compare(r, two_spots(100 / 1.1, 100 / 1.1), CompareOptions{});
  EXPECT_EQ(v.scales[0].how, "fitted");
  EXPECT_NEAR(v.scales[0].factor, 2.0 / 1.1, 1e-9);
  EXPECT_FALSE(v.differs());
  const auto j = v.to_json();
  EXPECT_EQ(j["summary"]["verdict"], "agrees");
  EXPECT_EQ(j["summary"]["scales"][0]["how"], "fitted");
}

// A (4·side)² XYZ rendering of Y = 100 with relative noise `sd` per pixel (white, or a 2 × 2 block filter: unit
// variance, neighbours correlated 0.5, diagonals 0.25) and a linear ramp of `ramp` per pixel, and 16 spots of
// side × side pixels on it, each read exactly. `textured`: that spot (row-major) carries a ±30 % checkerboard as
// well — the scene's texture, not the renderer's noise — its measured value the checkerboard's mean.
struct NoisyGrid {
  Rendering rendering;
  MeasuredScene scene;
};
NoisyGrid noisy_grid(double sd, bool correlated, double ramp, int side = 10, int textured = -1) {
  const int n = 4 * side;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01(0, 1);
  std::vector<double> white(static_cast<std::size_t>((n + 1) * (n + 1)));
  for (auto& x : white) x = n01(rng);
  Rendering r = flat_xyz(0);
  r.width = r.height = n;
  r.pixels.assign(static_cast<std::size_t>(n * n * 3), 0.0f);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const auto at = [&](int dx, int dy) { return white[static_cast<std::size_t>((y + dy) * (n + 1) + x + dx)]; };
      const double e = correlated ? 0.5 * (at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1)) : at(0, 0);
      const bool in_texture = (y / side) * 4 + x / side == textured;
      const double texture = in_texture ? ((x + y) % 2 ? 1.3 : 0.7) : 1.0;
      const double v = 100 * (1 + ramp * x) * (1 + sd * e) * texture;
      for (int c = 0; c < 3; ++c) r.pixels[static_cast<std::size_t>((y * n + x) * 3 + c)] = static_cast<float>(v);
    }
  MeasuredScene m;
  for (int i = 0; i < 16; ++i) {
    SpotMeasurement s;
    s.row = i / 4;
    s.col = i % 4;
    s.rendering_region = {side * s.col, side * s.row, side, side};
    s.luminance_cd_m2 = 100 * (1 + ramp * (side * s.col + 0.5 * (side - 1)));
    s.reading_sd = 1e-6;
    m.spots.push_back(s);
  }
  return {std::move(r), std::move(m)};
}

double stated_rendering_noise(double sd, bool correlated, double ramp, int side = 10) {
  const auto g = noisy_grid(sd, correlated, ramp, side);
  CompareOptions o;
  o.scale = 1.0;
  const auto v = compare(g.rendering, g.scene, o);
  double sum = 0;  // the stated standard uncertainty of each spot's mean, relative, averaged over the spots
  for (const auto& c : v.comparisons)
    for (const auto& [source, u] : c.budget)
      if (source == "rendering noise") sum += u;  // the budget is relative for light: u / measured
  return sum / static_cast<double>(v.comparisons.size());
}

double budget_of(const Comparison& c, const std::string& source) {
  for (const auto& [name, u] : c.budget)
    if (name == source) return u;
  return 0;
}

// The screen's left-out regions are in the result (issue 23's loose end): a spot whose pixels are the scene's
// texture, ±30 % against 2 % noise — its level ~225 times its neighbours', far past the screen's 99.99 % quantile —
// is named, per kind in the summary and on its comparison, and its band is its own spread; a faithful rendering
// names none. Through the stored body and back, and refused when it contradicts "rendering_noise": false.
TEST(VerifyCompare, TheNoiseScreensLeftOutRegionsAreNamedInTheResult) {
  CompareOptions o;
  o.scale = 1.0;
  const auto faithful = noisy_grid(0.02, false, 0);
  const auto clean = compare(faithful.rendering, faithful.scene, o).to_json();
  ASSERT_TRUE(clean["summary"]["kinds"]["light_spot"]["rendering_noise_left_out"].is_array());
  EXPECT_TRUE(clean["summary"]["kinds"]["light_spot"]["rendering_noise_left_out"].empty()) << clean["summary"].dump();
  for (const auto& c : clean["comparisons"]) EXPECT_EQ(c["noise_left_out"], false);

  const auto textured = noisy_grid(0.02, false, 0, 10, 5);  // r1c1
  const auto v = compare(textured.rendering, textured.scene, o);
  const auto j = v.to_json();
  EXPECT_EQ(j["summary"]["kinds"]["light_spot"]["rendering_noise_left_out"], nlohmann::json::array({"r1c1"})) << j["summary"].dump();
  for (std::size_t i = 0; i < v.comparisons.size(); ++i) {
    EXPECT_EQ(j["comparisons"][i]["noise_left_out"], v.comparisons[i].where == "r1c1") << v.comparisons[i].where;
    // Its band is its own spread: a checkerboard of ±30 % over 96 residual degrees of freedom states ~0.3/√100 = 3 %,
    // where the pooled noise of its neighbours would have said 2 %/√100 = 0.2 %.
    const double u = budget_of(v.comparisons[i], "rendering noise");
    if (v.comparisons[i].where == "r1c1") EXPECT_NEAR(u / 0.03, 1.0, 0.1) << u;
    else EXPECT_NEAR(u / 0.002, 1.0, 0.25) << v.comparisons[i].where << " " << u;
  }
  const auto s = stored_from_request(store_request(v, "render.exr", {"run-1"}, o));
  EXPECT_EQ(s.summary["kinds"]["light_spot"]["rendering_noise_left_out"], nlohmann::json::array({"r1c1"}));
  auto contradiction = store_request(v, "render.exr", {"run-1"}, o);
  contradiction["rendering_noise"] = false;
  for (auto& c : contradiction["result"]["comparisons"]) c["budget"].erase("rendering noise");
  try {
    stored_from_request(contradiction);
    ADD_FAILURE() << "a left-out region without the rendering's noise was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("noise_left_out"), std::string::npos) << e.what();
  }
  auto mistyped = store_request(v, "render.exr", {"run-1"}, o);
  mistyped["result"]["comparisons"][0]["noise_left_out"] = "yes";
  EXPECT_THROW(stored_from_request(mistyped), Error);
}

TEST(VerifyCompare, TheRenderingsOwnNoiseIsStatedFromItsPixels) {
  // White: σ / √100. The 2 × 2 filter: the variance of a 10 × 10 mean is (100 + 2·(0.5·90·2 + 0.25·81·2)) / 100² of a
  // pixel's, i.e. σ · 0.19 — not σ / 10. Bounds, from the estimator's spread over seeds (a review's simulation of
  // this setup: stated / true σ has mean 1.04 and sd 0.064 for white noise — the pooled variance of 8 × 97
  // residuals alone has a relative σ of 5 %, the neighbour correlations' own estimates add the rest — and sd 0.085
  // for the filtered noise): ±25 % and ±30 %, about 3.3σ, so the check holds for any seed, not only this one.
  // A ramp without noise is the scene, not noise: nothing stated.
  EXPECT_NEAR(stated_rendering_noise(0.02, false, 0) / 0.002, 1.0, 0.25);
  EXPECT_NEAR(stated_rendering_noise(0.02, true, 0) / (0.02 * 0.19), 1.0, 0.30);
  EXPECT_LT(stated_rendering_noise(0, false, 0.01), 1e-6);
  EXPECT_NEAR(stated_rendering_noise(0.02, false, 0.01) / 0.002, 1.0, 0.25);
  // 40 × 40 spots: the noise is read in each one's central 24 × 24, the mean's σ is of all 1600 pixels (σ/40).
  EXPECT_NEAR(stated_rendering_noise(0.02, false, 0, 40) / 0.0005, 1.0, 0.25);
}

TEST(VerifyCompare, BadInputsAreTypedErrors) {
  const auto r = flat_xyz(50);
  auto expect_class = [](auto f, ErrorClass cls) {
    try {
      f();
      FAIL() << "no error";
    } catch (const Error& e) {
      EXPECT_EQ(e.cls(), cls) << e.what();
    }
  };
  expect_class([&] { compare(r, MeasuredScene{}); }, ErrorClass::bad_parameter);
  auto outside = two_spots(1, 1);
  outside.spots[1].rendering_region = {18, 2, 4, 4};
  expect_class([&] { compare(r, outside); }, ErrorClass::bad_data);
  CompareOptions neg;
  neg.scale = -1;
  expect_class([&] { compare(r, two_spots(1, 1), neg); }, ErrorClass::bad_parameter);
  expect_class([&] { compare(Rendering{}, two_spots(1, 1)); }, ErrorClass::bad_data);
}

TEST(VerifyCompare, StoredLikeARunWithAnExitStatus) {
  const auto r = flat_xyz(50);
  CompareOptions given;
  given.scale = 2.0;
  const auto ok = compare(r, two_spots(100, 100), given);
  EXPECT_EQ(exit_status(ok), kExitAgrees);
  const auto bad = compare(r, two_spots(100, 80), given);  // the second spot: rendered 25 % too bright
  EXPECT_EQ(exit_status(bad), kExitDiffers);
  const auto s = to_store(bad, "render.exr", {"run-1", "run-2"}, given);
  ASSERT_EQ(s.measurements.size(), 2u);
  EXPECT_EQ(s.measurements[1].step, "light_spot/r0c1");
  EXPECT_NEAR(*s.measurements[1].value, 0.25, 1e-12);
  EXPECT_EQ(s.measurements[1].data["verdict"], "differs");
  EXPECT_NE(s.measurements[0].step, s.measurements[1].step);  // steps are unique within a run
  EXPECT_EQ(s.summary["verdict"], "differs");
  EXPECT_EQ(s.summary["kinds"]["light_spot"]["renderer_wrong_at"][0]["where"], "r0c1");
  EXPECT_EQ(s.params["against"].size(), 2u);
  EXPECT_EQ(s.params["scale"], 2.0);
  EXPECT_EQ(s.params["rendering_noise"], true);
  EXPECT_EQ(s.params["noise_neighbours"], 8);
  EXPECT_EQ(s.params["noise_pooling"], "median-screen");
}

TEST(VerifyCompare, TheRenderingNoiseOptionsTravelThroughTheRequestBody) {
  const auto r = flat_xyz(50);
  CompareOptions o;
  o.scale = 2.0;
  o.noise_neighbours = 3;
  const auto v = compare(r, two_spots(100, 80), o);
  auto s = stored_from_request(store_request(v, "render.exr", {"run-1"}, o));
  EXPECT_EQ(s.params["rendering_noise"], true);
  EXPECT_EQ(s.params["noise_neighbours"], 3);
  CompareOptions off = o;
  off.rendering_noise = false;
  const auto v_off = compare(r, two_spots(100, 80), off);
  for (const auto& c : v_off.comparisons)
    for (const auto& [source, u] : c.budget) EXPECT_NE(source, "rendering noise");
  s = stored_from_request(store_request(v_off, "render.exr", {"run-1"}, off));
  EXPECT_EQ(s.params["rendering_noise"], false);
  EXPECT_TRUE(s.params["noise_neighbours"].is_null());
  EXPECT_TRUE(s.params["noise_pooling"].is_null());
  // A body from before the fields existed: made the only way there was then, on over 8 regions; how it was pooled
  // (plain sums before the robust screen, the screen after) the body cannot say: not recorded.
  auto old = store_request(v, "render.exr", {"run-1"}, CompareOptions{});
  EXPECT_EQ(old["noise_pooling"], "median-screen");
  old.erase("rendering_noise");
  old.erase("noise_neighbours");
  old.erase("noise_pooling");
  s = stored_from_request(old);
  EXPECT_EQ(s.params["rendering_noise"], true);
  EXPECT_EQ(s.params["noise_neighbours"], 8);
  ASSERT_TRUE(s.params.contains("noise_pooling"));
  EXPECT_TRUE(s.params["noise_pooling"].is_null());
  // JSON's one number type: 8.0 (a Python float, a JavaScript number) is the whole number 8.
  auto as_double = store_request(v, "render.exr", {"run-1"}, o);
  as_double["noise_neighbours"] = 8.0;
  ASSERT_TRUE(as_double.dump().find("\"noise_neighbours\":8.0") != std::string::npos) << as_double.dump();
  s = stored_from_request(nlohmann::json::parse(as_double.dump()));
  EXPECT_TRUE(s.params["noise_neighbours"].is_number_integer());
  EXPECT_EQ(s.params["noise_neighbours"], 8);
  // Bad values, and a budget that contradicts "rendering_noise": false, are bad parameters naming the field.
  const std::pair<const char*, nlohmann::json> bad[] = {
      {"rendering_noise", "yes"},
      {"rendering_noise", 1},
      {"noise_neighbours", 0},
      {"noise_neighbours", -4},
      {"noise_neighbours", 2.5},
      {"noise_neighbours", 8.5},
      {"noise_neighbours", 0.0},
      {"noise_neighbours", -8.0},
      {"noise_neighbours", 1e300},
      {"noise_neighbours", 4294967304.0},  // 2^32 + 8: whole, and 8 if it were wrapped into an int
      {"noise_neighbours", std::numeric_limits<double>::quiet_NaN()},
      {"noise_neighbours", std::numeric_limits<double>::infinity()},
      {"noise_neighbours", "8"},
      {"noise_neighbours", "8.0"},
      {"noise_neighbours", nlohmann::json::array({8})},
      {"noise_neighbours", 1ll << 40},
      {"noise_neighbours", true},
      {"noise_pooling", "sum"},  // this engine's body cannot have pooled otherwise
      {"noise_pooling", 1},
      {"k", 0},
      {"k", -2},
  };
  for (const auto& [field, value] : bad) {
    auto body = store_request(v, "render.exr", {"run-1"}, o);
    body[field] = value;
    try {
      stored_from_request(body);
      ADD_FAILURE() << field << " = " << value.dump() << " was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.cls(), ErrorClass::bad_parameter);
      EXPECT_NE(std::string(e.what()).find(std::string("body.") + field), std::string::npos) << e.what();
    }
  }
  auto contradiction = store_request(v, "render.exr", {"run-1"}, o);  // its budgets carry the rendering's noise
  contradiction["rendering_noise"] = false;
  EXPECT_THROW(stored_from_request(contradiction), Error);
}

// A verification stored before `noise_pooling` existed (its params without the key, as the store holds them) reads
// back with it null — not recorded — and one stored since keeps its own.
TEST(VerifyCompare, AStoredVerificationWithoutItsPoolingReadsBackAsNotRecorded) {
  const nlohmann::json old_row = {{"rendering", "box.exr"}, {"against", {"run-1"}}, {"scale", 1}, {"k", 2}, {"rendering_noise", true}, {"noise_neighbours", 8}};
  const auto back = params_read_back(old_row);
  ASSERT_TRUE(back.contains("noise_pooling"));
  EXPECT_TRUE(back["noise_pooling"].is_null());
  EXPECT_EQ(back["noise_neighbours"], 8);
  auto today = old_row;
  today["noise_pooling"] = "median-screen";
  EXPECT_EQ(params_read_back(today), today);
}

}  // namespace
}  // namespace colorlab::verify
