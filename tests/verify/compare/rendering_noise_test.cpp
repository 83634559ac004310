// The rendering's own noise pooled robustly (issue 23, docs/verify.md "The uncertainty, source by source"): a region
// whose residuals are not noise — a textured patch, a spot over an edge — must not widen its neighbours' bands.
// The truth is the synthetic lab's (synthetic_lab.cpp): a rendering with a known noise σ per pixel, a texture of
// known amplitude written into one region with its mean left exactly as it was (so the texture is the scene, and
// that region's own comparison has nothing to flag), and a planted defect of known size beside it.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "colorlab/core/error.hpp"
#include "colorlab/verify/compare/verification.hpp"
#include "rendering_noise.hpp"
#include "rendering_sample.hpp"
#include "synthetic_lab.hpp"
#include "tally.hpp"

namespace colorlab::verify::testing {
namespace {

const SyntheticLab& lab() {
  static const SyntheticLab l;
  return l;
}

// A checkerboard of relative amplitude `a` over the region, less its own mean so the region's mean is unchanged:
// the largest residual a plane cannot take up, as a woven or printed texture, or a region catching a sharp edge.
Rendering textured(Rendering r, const PixelRect& g, double a) {
  double mean = 0;
  for (int y = 0; y < g.h; ++y)
    for (int x = 0; x < g.w; ++x) mean += (x + y) % 2 ? -1.0 : 1.0;
  mean /= g.w * g.h;
  const auto n = static_cast<std::size_t>(r.channels());
  for (int y = 0; y < g.h; ++y)
    for (int x = 0; x < g.w; ++x) {
      const double f = 1 + a * (((x + y) % 2 ? -1.0 : 1.0) - mean);
      float* p = r.pixels.data() + (static_cast<std::size_t>(g.y + y) * static_cast<std::size_t>(r.width) + static_cast<std::size_t>(g.x + x)) * n;
      for (std::size_t c = 0; c < n; ++c) p[c] = static_cast<float>(p[c] * f);
    }
  return r;
}

std::string patch_id(int i) { return std::string(1, static_cast<char>('A' + i % 14)) + std::to_string(1 + i / 14); }

TEST(VerifyRenderingNoise, ATexturedSpotLeavesItsNeighboursCalibrated) {
  // 200 draws of the truth with 4 % white noise per pixel (a spot's 9-pixel mean 1.3 %), against a measurement without
  // noise: the rendering's noise is the only source, so the truth must be inside the k = 2 band 93–97 % of the time
  // (issue 23) — also at the four spots beside r3c4, whose 3 × 3 region carries a ±30 % checkerboard (its residual
  // variance 0.09 per pixel, 56 times the noise's 0.0016). Measured with the pooling before (plain sums over the 8
  // nearest regions, the correlation's shape from plain sums over all): beside the texture the truth was inside the
  // band in 100.00 % of 800 comparisons per kind (their stated variance ~8 times too large), and everywhere else in
  // only 87.83 % of 15 000 — the checkerboard's residuals dominated the correlation's estimate, made the whole
  // rendering's noise look anti-correlated and every band too narrow. Both bounds failed. After: 94.50 % and 95.73 %.
  const Sources none{false, false, false, false, false, false};
  std::mt19937_64 first(1);
  const PixelRect spot = lab().measure(first, none).spots[3 * SyntheticLab::kCols + 4].rendering_region;
  const Rendering truth = textured(lab().render(), spot, 0.30);
  CompareOptions o;
  o.scale = 1.0;
  auto beside = [](const Comparison& c) {
    return c.kind.rfind("light", 0) == 0 && (c.where == "r2c4" || c.where == "r4c4" || c.where == "r3c3" || c.where == "r3c5");
  };
  Tally t;
  for (int d = 0; d < 200; ++d) {
    std::mt19937_64 rng(31000 + static_cast<std::uint64_t>(d));
    MeasuredScene m = lab().measure(rng, none);
    m.characterization.reset();
    m.black_box.reset();
    const Verification v = compare(with_render_noise(truth, rng, 0.04, false), m, o);
    Verification rest;  // the textured spot itself is judged by its own spread: not part of the count
    for (const auto& c : v.comparisons)
      if (c.where != "r3c4") rest.comparisons.push_back(c);
    t.add(rest, beside);
  }
  t.print("rendering noise alone (4 %), spot r3c4 textured ±30 %");
  for (const char* kind : {"light_spot", "light_floor"}) {
    ASSERT_TRUE(t.at.count(kind));
    EXPECT_GE(1 - t.at.at(kind).rate(), 0.93) << kind << " beside the textured spot";
    EXPECT_LE(1 - t.at.at(kind).rate(), 0.97) << kind << " beside the textured spot";
    EXPECT_GE(1 - t.elsewhere.at(kind).rate(), 0.93) << kind << " elsewhere";
    EXPECT_LE(1 - t.elsewhere.at(kind).rate(), 0.97) << kind << " elsewhere";
  }
}

TEST(VerifyRenderingNoise, ATexturedPatchNoLongerHidesADefectBesideIt) {
  // Patch 40 (M3: column 12, row 2 of the 14 × 10 chart) 3 ΔE00 off, patch 41 (N3) beside it carrying a ±80 %
  // checkerboard (a black-and-white weave or halftone at pixel scale; mean unchanged), 2 % noise per pixel in the
  // rendering, every measurement source drawn: the defect must be flagged in ≥ 90 % of 100 draws in §7.3 and §7.4,
  // the other patches ≤ 5 % (the textured one aside). Measured with the pooling before (plain sums over the 8 nearest
  // patches, N3 among them): M3's band ±3.46 ΔE00 on average, the defect flagged in 11 % (§7.3) and 9 % (§7.4) of
  // the draws — masked; with a ±50 % checkerboard the band was ±2.33 ΔE00 and the defect still seen. After: M3's
  // band ±0.49 ΔE00, flagged in 100 % and 100 %.
  constexpr int kPatch = 40, kTexture = 41;
  Defects d;
  d.patch = kPatch;
  d.patch_factor = lab().factor_for_de00(kPatch, 3.0);
  std::mt19937_64 first(1);
  const PixelRect g = lab().measure(first, Sources{}).patches[kTexture].rendering_region;
  constexpr double kAmplitude = 0.80;
  const Rendering r = textured(lab().render(d), g, kAmplitude);
  CompareOptions o;
  o.scale = 1.0;
  const std::string at = patch_id(kPatch), texture = patch_id(kTexture);
  Tally t;
  double band = 0;
  int bands = 0;
  for (int k = 0; k < 100; ++k) {
    std::mt19937_64 rng(32000 + static_cast<std::uint64_t>(k));
    const MeasuredScene m = lab().measure(rng, Sources{});
    const Verification v = compare(with_render_noise(r, rng, 0.02, false), m, o);
    Verification rest;
    for (const auto& c : v.comparisons) {
      if (c.where == texture && c.kind.rfind("colour", 0) == 0) continue;
      if (c.where == at && c.kind == "colour_7_3") band += c.expanded, ++bands;
      rest.comparisons.push_back(c);
    }
    t.add(rest, [&](const Comparison& c) { return c.where == at && c.kind.rfind("colour", 0) == 0; });
  }
  t.print(("patch " + at + " 3 dE00 off beside " + texture + " textured ±" + std::to_string(static_cast<int>(100 * kAmplitude)) +
           " %, 2 % rendering noise")
              .c_str());
  std::printf("  the band at %s: ±%.2f dE00 on average\n", at.c_str(), band / bands);
  for (const char* kind : {"colour_7_3", "colour_7_4"}) {
    ASSERT_TRUE(t.at.count(kind));
    EXPECT_GE(t.at.at(kind).rate(), 0.90) << kind << ": the defect beside the texture";
  }
  EXPECT_LE(t.all_elsewhere.rate(), 0.05);
}

TEST(VerifyRenderingNoise, TheScreenLeavesOutTheTextureAndAlmostNoCleanRegion) {
  // The screen's false alarms, counted where it runs: 100 renderings with 4 % noise per pixel, white and 2 × 2-
  // correlated (fewer degrees of freedom per region, which the screen must allow for), over the 80 spots (3 × 3) and
  // the 140 patches (5 × 5, three coordinates). A clean region left out is judged by its own few pixels and its
  // neighbours lose a top-of-the-tail value: a simulation of the median test says 0.07–0.18 % of clean regions;
  // the bound, 0.5 %, is ~15 binomial σ above that over 22 000 regions, and a screen whose degrees of freedom ignored
  // the correlation would exceed it. The textured region must be left out every time.
  const Sources none{false, false, false, false, false, false};
  std::mt19937_64 first(1);
  const MeasuredScene m = lab().measure(first, none);
  std::vector<PixelRect> spots, patches;
  for (const auto& s : m.spots) spots.push_back(s.rendering_region);
  for (const auto& p : m.patches) patches.push_back(p.rendering_region);
  constexpr std::size_t kTextured = 3 * SyntheticLab::kCols + 4;
  const Rendering truth = textured(lab().render(), spots[kTextured], 0.30);
  const detail::ToXyz tx(truth);
  for (const bool correlated : {false, true}) {
    long clean = 0, left_out = 0, texture_kept = 0;
    for (int d = 0; d < 100; ++d) {
      std::mt19937_64 rng(33000 + static_cast<std::uint64_t>(d));
      const Rendering r = with_render_noise(truth, rng, 0.04, correlated);
      const auto on_spots = detail::rendering_noise(r, spots, tx.matrix().row(1), 8);
      const auto on_patches = detail::rendering_noise(r, patches, tx.matrix(), 8);
      ASSERT_EQ(on_spots.left_out.size(), spots.size());
      ASSERT_EQ(on_patches.left_out.size(), patches.size());
      for (std::size_t i = 0; i < spots.size(); ++i) {
        if (i == kTextured) {
          texture_kept += on_spots.left_out[i] ? 0 : 1;
          continue;
        }
        ++clean;
        left_out += on_spots.left_out[i] ? 1 : 0;
      }
      for (const bool l : on_patches.left_out) ++clean, left_out += l ? 1 : 0;
    }
    std::printf("the screen, %s noise: %ld of %ld clean regions left out (%.3f %%); the textured spot kept %ld times of 100\n",
                correlated ? "correlated" : "white", left_out, clean, 100.0 * static_cast<double>(left_out) / static_cast<double>(clean),
                texture_kept);
    EXPECT_LE(static_cast<double>(left_out) / static_cast<double>(clean), 0.005) << (correlated ? "correlated" : "white");
    EXPECT_EQ(texture_kept, 0) << (correlated ? "correlated" : "white");
  }
}

TEST(VerifyRenderingNoise, NeighboursBelowOneAreABadParameter) {
  const Rendering r = lab().render();
  std::mt19937_64 rng(3);
  const MeasuredScene m = lab().measure(rng, Sources{});
  for (const int n : {0, -1, -8}) {
    CompareOptions o;
    o.noise_neighbours = n;
    try {
      compare(r, m, o);
      ADD_FAILURE() << "noise_neighbours " << n << " was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.cls(), ErrorClass::bad_parameter) << e.what();
      EXPECT_NE(std::string(e.what()).find("noise_neighbours"), std::string::npos) << e.what();
    }
  }
  // Off: no comparison has the source (the count is still checked: a contradictory request is not guessed at).
  CompareOptions off;
  off.rendering_noise = false;
  for (const auto& c : compare(r, m, off).comparisons)
    for (const auto& [source, u] : c.budget) EXPECT_NE(source, "rendering noise") << c.kind << " " << c.where;
}

}  // namespace
}  // namespace colorlab::verify::testing
