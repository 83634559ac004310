// The pieces of the comparison on inputs with an answer on paper: the coverage arithmetic, the Mahalanobis verdict,
// the scale reported, and typed errors for bad inputs.
#include <gtest/gtest.h>

#include <cmath>

#include "colorlab/core/error.hpp"
#include "colorlab/verify/compare/stored.hpp"
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
}

}  // namespace
}  // namespace colorlab::verify
