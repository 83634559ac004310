// Is the stated uncertainty calibrated? Over 200 noise draws of the simulated measurement of a faithful rendering
// (the truth itself), the truth must fall inside the k = 2 band in 93–97 % of the comparisons (issue 23), in all
// and for each source that can be made the only one.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "colorlab/verify/compare/verification.hpp"
#include "synthetic_lab.hpp"
#include "tally.hpp"

namespace colorlab::verify::testing {
namespace {

constexpr int kDraws = 200;

const SyntheticLab& lab() {
  static const SyntheticLab l;
  return l;
}

// Coverage per kind over the draws: the share of comparisons of the truth that agree.
// `only`: keep just the comparisons of this kind (the others would be computed for nothing).
// A renderer with noise of its own: the pixel's relative standard deviation, white or correlated between neighbours.
struct RenderNoise {
  double sd = 0;
  bool correlated = false;
  bool per_band = false;
};

std::map<std::string, Count> run(const Sources& s, std::uint64_t seed0, const std::string& only = {}, int draws = kDraws,
                                 RenderNoise noise = {}) {
  const Rendering truth = lab().render();
  CompareOptions o;
  o.scale = 1.0;  // the synthetic renderer's units: W·m⁻²·sr⁻¹·nm⁻¹, so luminance comes out in cd/m²
  Tally t;
  for (int d = 0; d < draws; ++d) {
    std::mt19937_64 rng(seed0 + static_cast<std::uint64_t>(d));
    MeasuredScene m = lab().measure(rng, s);
    if (!only.empty()) {
      if (only != "colour_7_3") m.characterization.reset();
      if (only != "colour_7_4") m.black_box.reset();
      if (only != "light_spot") m.spots.clear();
      if (only != "light_floor") m.floor.clear();
    }
    const auto nowhere = [](const Comparison&) { return false; };
    if (noise.sd > 0) {
      m.characterization.reset();  // §7.3 keeps its mapping's model error: not judged with the rendering's noise
      t.add(compare(with_render_noise(truth, rng, noise.sd, noise.correlated, noise.per_band), m, o), nowhere);
    } else {
      t.add(compare(truth, m, o), nowhere);
    }
  }
  return t.elsewhere;
}

double coverage(const Count& c) { return 1.0 - c.rate(); }

TEST(VerifyCalibration, AllSourcesTogether) {
  const auto kinds = run(Sources{}, 1000);
  Count all;
  for (const auto& [kind, c] : kinds) {
    std::printf("all sources: %-12s truth inside the band in %6.2f %% of %ld\n", kind.c_str(), 100 * coverage(c), c.n);
    all.n += c.n;
    all.flagged += c.flagged;
    EXPECT_GE(coverage(c), 0.93) << kind;
    EXPECT_LE(coverage(c), 0.97) << kind;
  }
  std::printf("all sources: every kind  truth inside the band in %6.2f %% of %ld\n", 100 * coverage(all), all.n);
  EXPECT_GE(coverage(all), 0.93);
  EXPECT_LE(coverage(all), 0.97);
}

struct OneSource {
  const char* name;
  Sources sources;
  const char* kind;  // the comparison where this source is the only one
  bool bound;        // a bound (rectangular), not a distribution: covered entirely at k = 2
};

TEST(VerifyCalibration, EachSourceAlone) {
  auto only = [](auto set) {
    Sources s{false, false, false, false, false, false};
    set(s);
    return s;
  };
  const OneSource cases[] = {
      {"frame noise", only([](Sources& s) { s.frame_noise = true; }), "colour_7_4", false},
      {"ls110 repeatability", only([](Sources& s) { s.ls110 = true; }), "light_spot", false},
      {"misregistration", only([](Sources& s) { s.misregistration = true; }), "light_spot", false},
      {"floor map", only([](Sources& s) { s.floor_map = true; }), "light_floor", false},
      {"lamp drift", only([](Sources& s) { s.drift = true; }), "light_spot", true},
  };
  std::uint64_t seed = 5000;
  for (const auto& c : cases) {
    const auto kinds = run(c.sources, seed, c.kind);
    seed += 1000;
    const Count& k = kinds.at(c.kind);
    std::printf("%-20s alone (%s): truth inside the band in %6.2f %% of %ld\n", c.name, c.kind, 100 * coverage(k), k.n);
    if (c.bound) {
      // u = bound/√3 and k = 2 reach 1.15 × the bound: a rectangular source is always inside.
      EXPECT_EQ(coverage(k), 1.0) << c.name;
    } else {
      EXPECT_GE(coverage(k), 0.93) << c.name;
      EXPECT_LE(coverage(k), 0.97) << c.name;
    }
  }
}

TEST(VerifyCalibration, TheRenderingsOwnNoiseAlone) {
  // A renderer's noisy estimate of the truth against a measurement without noise: the only difference is the
  // rendering's own, which the engine estimates from the rendering itself (each region's spread, pooled over its
  // neighbours, with the noise's correlation). 4 % per pixel: a patch's mean (25 pixels) 0.8 %, a spot's (9) 1.3 %,
  // far above what is left of the measurement. Correlated noise (a 2 × 2 filter) makes a region's mean 1.6–1.8
  // times as uncertain as its pixel count says: a source blind to correlation would cover ~70 % of it.
  // §7.3 keeps its fitted mapping's model error (below), so it is not judged here.
  //
  // §7.4 is judged with noise of its own in each band: noise shared by every band (one seed for all, as Blender
  // renders them) moves a patch's raw counts along one direction only, and a 3-D verdict (threshold √χ²₃ = 2.83)
  // covers a one-dimensional difference 99.5 % of the time — conservative by the verdict's design, not by the
  // source's size; that case is printed, and checked only not to under-cover.
  const Sources none{false, false, false, false, false, false};
  std::uint64_t seed = 20000;
  for (const bool correlated : {false, true}) {
    const auto kinds = run(none, seed, {}, kDraws, {0.04, correlated});
    seed += 1000;
    for (const char* kind : {"light_spot", "light_floor", "colour_7_4"}) {
      const Count& k = kinds.at(kind);
      const bool one_direction = std::string(kind) == "colour_7_4";
      std::printf("rendering noise alone, %s%s (%s): truth inside the band in %6.2f %% of %ld\n", correlated ? "correlated" : "white",
                  one_direction ? ", every band alike" : "", kind, 100 * coverage(k), k.n);
      EXPECT_GE(coverage(k), 0.93) << kind << (correlated ? " correlated" : " white");
      if (!one_direction) EXPECT_LE(coverage(k), 0.97) << kind << (correlated ? " correlated" : " white");
    }
  }
  const auto kinds = run(none, seed, "colour_7_4", kDraws, {0.04, false, true});
  const Count& k = kinds.at("colour_7_4");
  std::printf("rendering noise alone, white, each band its own (colour_7_4): truth inside the band in %6.2f %% of %ld\n",
              100 * coverage(k), k.n);
  EXPECT_GE(coverage(k), 0.93);
  EXPECT_LE(coverage(k), 0.97);
}

TEST(VerifyCalibration, TheChartReadsOwnNoiseIsInsideTheHeldOutErrors) {
  // The renderer is given the chart-read's spectra, one reading per patch with the instrument's noise (here a 3 %
  // gain per patch and 1 % per band, larger than a Spectrolino's so that it matters beside the mapping's own error),
  // while the camera photographed the true chart. The colour half from runs has no source for that noise: the
  // characterization and the black box are fitted against the same chart-read, so their held-out errors carry its
  // variance (docs/verify.md "Not yet done"). 200 draws, every source, colour only: with the mappings fitted against
  // the read spectra the truth must be inside the k = 2 band 93–97 % (issue 23); fitted against the true spectra (a
  // budget without the reading noise, the same rendering) it must fall below 93 % — the noise is large enough here
  // that leaving it out shows, so the first bound is a statement about the budget, not about a negligible source.
  auto run_read = [](bool read_is_reference, std::uint64_t seed0) {
    Sources s;
    s.read_gain_sd = 0.03;
    s.read_band_sd = 0.01;
    s.read_is_reference = read_is_reference;
    CompareOptions o;
    o.scale = 1.0;
    Tally t;
    for (int d = 0; d < kDraws; ++d) {
      std::mt19937_64 rng(seed0 + static_cast<std::uint64_t>(d));
      Eigen::MatrixXd read;
      MeasuredScene m = lab().measure(rng, s, &read);
      m.spots.clear();
      m.floor.clear();
      t.add(compare(lab().render({}, &read), m, o), [](const Comparison&) { return false; });
    }
    return t.elsewhere;
  };
  const auto with = run_read(true, 70000), without = run_read(false, 70000);
  for (const char* kind : {"colour_7_3", "colour_7_4"}) {
    std::printf("chart-read noise (3 %% gain, 1 %% per band), %s: truth inside the band in %6.2f %% with the mapping fitted to the "
                "read spectra, %6.2f %% fitted to the true ones\n",
                kind, 100 * coverage(with.at(kind)), 100 * coverage(without.at(kind)));
    EXPECT_GE(coverage(with.at(kind)), 0.93) << kind;
    EXPECT_LE(coverage(with.at(kind)), 0.97) << kind;
    EXPECT_LT(coverage(without.at(kind)), 0.93) << kind;
  }
}

TEST(VerifyCalibration, CharacterizationsModelErrorAlone) {
  // No noise at all: the only difference left is the fitted mappings' own error (the camera is not a colorimeter,
  // the black box is smooth), judged against their cross-validated errors in the patch's region. It is the same
  // on every draw, so this is a statement about the 140 patches, not about repeated draws: the 93–97 % is
  // for noise draws. What is checked is that 140 patches are consistent with the band's nominal 95.45 %: at least
  // 95.45 % − 3 binomial σ (√(0.0455 · 0.9545 / 140) = 1.76 %) = 90.2 % of them inside.
  Sources s{false, false, false, false, false, true};
  const auto kinds = run(s, 9000, {}, 1);  // without noise every draw is the same
  for (const char* kind : {"colour_7_3", "colour_7_4"}) {
    const Count& k = kinds.at(kind);
    std::printf("characterization alone (%s): truth inside the band in %6.2f %% of %ld\n", kind, 100 * coverage(k), k.n);
    ASSERT_EQ(k.n, SyntheticLab::kPatches);
    EXPECT_GE(coverage(k), 0.902) << kind;
  }
}

}  // namespace
}  // namespace colorlab::verify::testing
