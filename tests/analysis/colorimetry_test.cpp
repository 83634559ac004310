// Colorimetry against published numbers: Sharma et al. (2005) CIEDE2000 pairs, CIE whites, the F2 white point,
// the Bradford D65→D50 matrix and the ICC sRGB/Adobe RGB colorants (via lcms2).
#include <gtest/gtest.h>

#include <cmath>

#include "colorlab/analysis/color_difference.hpp"
#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/csv.hpp"
#include "colorlab/analysis/rgb_spaces.hpp"
#include "test_support.hpp"

namespace ca = colorlab::analysis;

namespace {

TEST(AnalysisCiede2000, SharmaWuDalal34PairsTo1e4) {
  COLORLAB_REQUIRE_SHARED(file, "ciede2000_sharma2005_34pairs.csv");
  ca::CsvTable t = ca::read_csv(file);
  ASSERT_EQ(t.rows.size(), 34u);
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    auto n = [&](const char* col) { return t.number(r, t.require_column(col)); };
    ca::Lab a{n("L1"), n("a1"), n("b1")}, b{n("L2"), n("a2"), n("b2")};
    EXPECT_NEAR(ca::delta_e2000(a, b), n("dE00"), 1e-4) << "pair " << t.rows[r][0];
    EXPECT_NEAR(ca::delta_e2000(b, a), n("dE00"), 1e-4) << "pair " << t.rows[r][0] << " reversed";
  }
}

ca::IntegrationOptions plain_sum(double step) {
  ca::IntegrationOptions o;
  o.step_nm = step;
  o.extrapolate_reflectance = false;
  return o;
}

// CIE 1931 2° whites from plain sums (colorimetry-notes §2).
TEST(AnalysisWhites, PlainTenNanometreSumsMatchPublishedWhites) {
  const auto obs = ca::load_observer(ca::Observer::cie1931_2deg);
  const auto grid = ca::uniform_grid(380, 730, 10);
  struct W {
    const char* lamp;
    double X, Z;
  };
  for (W w : {W{"D50", 96.384, 82.453}, W{"D65", 95.012, 108.816}, W{"A", 109.815, 35.549}}) {
    ca::ReflectanceIntegrator integ(ca::load_illuminant(w.lamp), obs, grid, plain_sum(10));
    // colord's D50 table differs from CIE 15's computed D50 in the fifth digit; D65 and A are the CIE tables.
    const double tol = std::string(w.lamp) == "D50" ? 0.015 : 2e-3;
    EXPECT_NEAR(integ.white().X, w.X, tol) << w.lamp;
    EXPECT_NEAR(integ.white().Z, w.Z, tol) << w.lamp;
  }
  ca::ReflectanceIntegrator d50(ca::load_illuminant("D50"), obs, ca::uniform_grid(380, 780, 5), plain_sum(5));
  EXPECT_NEAR(d50.white().X, 96.420, 0.015);
  EXPECT_NEAR(d50.white().Z, 82.512, 0.015);
}

TEST(AnalysisWhites, FluorescentLampsNeedTheFineGrid) {
  const auto f2 = ca::load_illuminant("F2");
  ca::XyY fine = ca::xyz_to_xyy(ca::illuminant_white(f2, ca::Observer::cie1931_2deg));
  EXPECT_NEAR(fine.x, 0.3721, 1e-4);
  EXPECT_NEAR(fine.y, 0.3751, 1e-4);
  // The pitfall: a 10 nm subsample skips the mercury lines and moves the white point to (0.3881, 0.3927).
  ca::SpectralSet coarse = f2.select({0});
  std::vector<std::size_t> keep;
  std::vector<double> wl;
  for (std::size_t i = 0; i < f2.wavelengths.size(); ++i)
    if (std::fmod(f2.wavelengths[i], 10.0) == 0 && f2.wavelengths[i] <= 730) keep.push_back(i), wl.push_back(f2.wavelengths[i]);
  coarse.wavelengths = wl;
  coarse.values.resize(1, static_cast<Eigen::Index>(keep.size()));
  for (std::size_t i = 0; i < keep.size(); ++i) coarse.values(0, static_cast<Eigen::Index>(i)) = f2.values(0, static_cast<Eigen::Index>(keep[i]));
  ca::ReflectanceIntegrator sub(coarse, ca::load_observer(ca::Observer::cie1931_2deg), ca::uniform_grid(380, 730, 10),
                                plain_sum(10));
  ca::XyY bad = ca::xyz_to_xyy(sub.white());
  EXPECT_NEAR(bad.x, 0.3881, 5e-4);
  EXPECT_NEAR(bad.y, 0.3927, 5e-4);
}

TEST(AnalysisLab, SmallValueBranchAndRoundTrip) {
  const ca::Xyz white{95.0456, 100.0, 108.9058};
  // Below (6/29)³ L* is linear: 903.2963 · Y/Yn.
  ca::Lab dark = ca::xyz_to_lab({0.095, 0.1, 0.1089}, white);
  EXPECT_NEAR(dark.L, 0.001 * 24389.0 / 27.0, 1e-6);
  for (ca::Xyz c : {ca::Xyz{0.01, 0.02, 0.03}, ca::Xyz{20.654008, 12.197225, 5.136952}, ca::Xyz{90, 95, 40}}) {
    ca::Xyz back = ca::lab_to_xyz(ca::xyz_to_lab(c, white), white);
    EXPECT_NEAR(back.X, c.X, 1e-9);
    EXPECT_NEAR(back.Y, c.Y, 1e-9);
    EXPECT_NEAR(back.Z, c.Z, 1e-9);
  }
}

// colour-science's documented example (XYZ 0.20654008, 0.12197225, 0.05136952 under D65 xy 0.3127, 0.3290).
TEST(AnalysisLabLuv, PublishedExample) {
  const ca::Xyz white = ca::xyy_to_xyz({0.3127, 0.3290, 100});
  const ca::Xyz c{20.654008, 12.197225, 5.136952};
  ca::Lab lab = ca::xyz_to_lab(c, white);
  EXPECT_NEAR(lab.L, 41.5278752, 1e-4);
  EXPECT_NEAR(lab.a, 52.6385830, 1e-4);
  EXPECT_NEAR(lab.b, 26.9231792, 1e-4);
  ca::Luv luv = ca::xyz_to_luv(c, white);
  EXPECT_NEAR(luv.L, 41.5278752, 1e-4);
  EXPECT_NEAR(luv.u, 96.8362605, 1e-4);
  EXPECT_NEAR(luv.v, 17.7521014, 1e-4);
  EXPECT_NEAR(ca::delta_e_uv(luv, luv), 0.0, 1e-12);
}

// Bradford D65 → D50 as tabulated by Lindbloom (www.brucelindbloom.com).
TEST(AnalysisBradford, D65ToD50Matrix) {
  const ca::Xyz d65{95.047, 100, 108.883}, d50{96.422, 100, 82.521};
  const double M[3][3] = {{1.0478112, 0.0228866, -0.0501270}, {0.0295424, 0.9904844, -0.0170491}, {-0.0092345, 0.0150436, 0.7521316}};
  for (int j = 0; j < 3; ++j) {
    ca::Xyz e{j == 0 ? 1.0 : 0.0, j == 1 ? 1.0 : 0.0, j == 2 ? 1.0 : 0.0};
    ca::Xyz r = ca::bradford_adapt(e, d65, d50);
    EXPECT_NEAR(r.X, M[0][j], 2e-6);
    EXPECT_NEAR(r.Y, M[1][j], 2e-6);
    EXPECT_NEAR(r.Z, M[2][j], 2e-6);
  }
  ca::Xyz w = ca::bradford_adapt(d65, d65, d50);
  EXPECT_NEAR(w.X, d50.X, 1e-9);
  EXPECT_NEAR(w.Z, d50.Z, 1e-9);
}

// ICC sRGB profile colorants (D50-adapted): red = 0.4361, 0.2225, 0.0139; Adobe RGB red = 0.6098, 0.3111, 0.0195.
TEST(AnalysisRgbSpaces, ColorantsAndWhiteThroughLcms) {
  auto s = ca::rgb_to_xyz_d50(ca::RgbSpace::srgb, {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
  EXPECT_NEAR(s[0].X, 43.607, 0.05);
  EXPECT_NEAR(s[0].Y, 22.250, 0.05);
  EXPECT_NEAR(s[1].Y, 71.688, 0.05);
  EXPECT_NEAR(s[2].Z, 71.417, 0.05);
  auto a = ca::rgb_to_xyz_d50(ca::RgbSpace::adobe_rgb_1998, {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
  EXPECT_NEAR(a[0].X, 60.976, 0.05);
  EXPECT_NEAR(a[0].Y, 31.112, 0.05);
  EXPECT_NEAR(a[1].Y, 62.566, 0.05);
  EXPECT_NEAR(a[2].Z, 74.484, 0.05);
  for (auto sp : {ca::RgbSpace::srgb, ca::RgbSpace::adobe_rgb_1998}) {
    auto lab = ca::rgb_to_lab_d50(sp, {{1, 1, 1}, {0.5, 0.5, 0.5}});
    EXPECT_NEAR(lab[0].L, 100, 0.01);
    EXPECT_NEAR(lab[0].a, 0, 0.01);
    EXPECT_NEAR(lab[1].b, 0, 0.01);
    auto rgb = ca::xyz_d50_to_rgb(sp, ca::rgb_to_xyz_d50(sp, {{0.2, 0.5, 0.7}}));
    EXPECT_NEAR(rgb[0][0], 0.2, 1e-4);
    EXPECT_NEAR(rgb[0][2], 0.7, 1e-4);
  }
  // Adobe RGB mid grey (0.5) is gamma 2.2: Y = 0.5^(563/256) · 100.
  auto g = ca::rgb_to_xyz_d50(ca::RgbSpace::adobe_rgb_1998, {{0.5, 0.5, 0.5}});
  EXPECT_NEAR(g[0].Y, 100 * std::pow(0.5, 563.0 / 256.0), 0.02);
}

TEST(AnalysisEmission, IlluminantWhiteEqualsReflectorWhite) {
  const auto d65 = ca::load_illuminant("D65");
  ca::Xyz e = ca::illuminant_white(d65, ca::Observer::cie1931_2deg);
  ca::ReflectanceIntegrator integ(d65, ca::load_observer(ca::Observer::cie1931_2deg), ca::uniform_grid(300, 830, 5));
  // Trapezoid (emission) vs rectangle (CIE 15 reflectance) sums differ only at the range ends.
  EXPECT_NEAR(e.X, integ.white().X, 0.02);
  EXPECT_NEAR(e.Z, integ.white().Z, 0.02);
  EXPECT_NEAR(e.X, 95.04, 0.02);
  EXPECT_NEAR(e.Z, 108.88, 0.02);
}

}  // namespace
