#pragma once
// Characterization across a lamp change (issue 26): a chart photographed under lamp A, a characterization for lamp B.
//
// Why: a mapping fitted under A and used under B carries the camera's departure from the Luther condition into every
// patch (1.5–4.8 ΔE00 mean for D65 → A / F11, docs/ACCURACY.md §2), and cross-validation under A cannot see it. But the
// lab has what it takes to photograph the chart under B without doing so: the chart's measured reflectances, B's
// spectrum, and the camera's sensitivities estimated from the photograph under A (§7.4, with a posterior). So:
//
//   1. sensitivities s_c from RAW_A = (reflectance × A) · s (estimate_sensitivities: the prior-based black box);
//   2. the chart predicted under B: RAW_B = (reflectance × B) · s, white-balanced by the perfect white under B, with
//      reference colours under B (Bradford-adapted to the ICC D50 white, as every other characterization here);
//   3. every model family fitted and selected (LOO) on that predicted chart, as under A;
//   4. the same chosen model refitted on charts predicted from curves drawn from the sensitivities' posterior (and,
//      when B is only named, under B's spectrum drawn about its standard): their spread at a patch is what the
//      sensitivities' credible bands and the lamp's uncertainty mean for that patch's colour.
//
// Inputs under B must be white-balanced the same way: camera RAW ÷ the RAW of a perfect (or known neutral) white
// under B.
#include <Eigen/Dense>
#include <array>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "colorlab/analysis/characterization.hpp"
#include "colorlab/analysis/sensitivity_prior.hpp"
#include "colorlab/analysis/spectral.hpp"

namespace colorlab::analysis {

// A lamp's spectrum and where it came from. A lab's TL84 is not CIE F11: the standard tables stand in only until the
// lamp is measured, and every characterization that rests on one says so (warning()).
struct LampSpectrum {
  std::string name;             // the lab's name for the lamp ("TL84", "A", "D65", …)
  SpectralSet spd;              // one row, any positive scale
  bool measured = false;        // false: the CIE standard the lamp is named after stands in for it
  std::string warning() const;  // empty when measured
};
// The CIE standard a cabinet lamp is named after: D65, D50, A, TL84 (→ F11), CWF (→ F2), F-series by name.
// Throws Error(not_found) with a hint for a lamp that has no standard.
LampSpectrum nominal_lamp(const std::string& lamp);
// A measured spectrum (one row, non-negative, not all zero); throws Error(bad_data) otherwise.
LampSpectrum measured_lamp(const std::string& lamp, SpectralSet spd);

struct RelightingGrids;  // relighting.cpp: what rebuilding a chart under another spectrum on the same grids reuses

// The chart under one lamp, precomputed so that a chart can be predicted from any curves cheaply.
struct ChartUnderLamp {
  std::string lamp;
  bool lamp_measured = false;
  std::string lamp_warning;         // LampSpectrum::warning(), carried into every characterization under this lamp
  std::vector<double> wavelengths;  // the curves' grid
  // n × bands: RAW = radiance · curveᵀ for a curve linear between the grid's wavelengths, integrated at 1 nm
  // (reflectances Sprague or cubic, lamp linear, so a fluorescent line between two bands counts in both).
  Eigen::MatrixXd radiance;
  Eigen::RowVectorXd white;  // the perfect white's row of `radiance`
  ChartData reference;       // ids, XYZ (CIE 1931 2° under the lamp, Bradford to ICC D50) and L*a*b*; rgb empty
  SpectralSet reflectances;  // what the chart was built from: kept so that it can be rebuilt under a drawn lamp
  SpectralSet lamp_spd;
  // The resampling that does not depend on the lamp's values (reflectances at 1 nm, the lamp's and the curves'
  // resampling matrices, the reference colours' integration grids): under() a spectrum on lamp_spd's wavelengths
  // reuses it — a posterior draw's chart then costs two small products, not six resampling matrices.
  std::shared_ptr<const RelightingGrids> grids;

  // rgb = RAW ÷ RAW of the perfect white under this lamp, per channel; curves: 3 × bands.
  ChartData predict(const Eigen::MatrixXd& curves) const;
  // The same chart under another spectrum for the same lamp (a draw of what a nominal lamp may really emit); the same
  // arithmetic as chart_under_lamp(reflectances, that spectrum, wavelengths).
  ChartUnderLamp under(const SpectralSet& spd) const;
};
// grid: the sensitivities' wavelengths (inside the reflectances' and the lamp's range).
ChartUnderLamp chart_under_lamp(const SpectralSet& reflectances, const LampSpectrum& lamp, const std::vector<double>& grid);

// What a lamp known only by its standard's name may really emit: the standard × exp(Σ a_k P_k(x)), P_k the Legendre
// polynomials of degree 1–3 over the sensitivities' grid (x ∈ [−1, 1], held at the ends outside it), a_k drawn
// N(0, kNominalLampLogSdev[k]). A real lamp departs from its standard smoothly (colour temperature, filter, phosphor
// blend: the tilt and bow of the ratio) and in its lines; the smooth part is what moves a chart's colours.
// The spreads are the coefficients fitted to ln(measured ÷ standard) over 400–720 nm for the one measured lamp in
// ../shared/data that is a real lamp of its standard's kind and that no test uses: the ISO 7589 studio tungsten
// against CIE A (−0.175, −0.002, 0.038; residual 0.012). (The Gretag booth's daylight against CIE D65, −0.139, −0.569,
// −0.119, is a simulator of a phase of daylight, not a lamp its standard describes; spreads from the RMS of both,
// 0.158 / 0.402 / 0.088, put the truth inside the band at 99.5 % pooled, wider than a 95 % band may be —
// docs/ACCURACY.md §6. The booth's A and CWF, the test lamps there, are not used to set them.)
inline constexpr std::array<double, 3> kNominalLampLogSdev = {0.175, 0.002, 0.038};
SpectralSet draw_nominal_lamp(const SpectralSet& standard, const std::vector<double>& grid, std::mt19937& rng);

// Spectral sensitivities with their posterior (the prior-based black box, blackbox.hpp).
struct SensitivityEstimate {
  std::vector<double> wavelengths;
  Eigen::MatrixXd curves;                     // 3 × bands, in the RAW's units per unit of ChartUnderLamp::radiance
  std::array<Eigen::MatrixXd, 3> covariance;  // per channel, bands × bands
  // One set of curves drawn from the (Gaussian) posterior, clipped at 0 as the sensitivities are.
  Eigen::MatrixXd draw(std::mt19937& rng) const;
};
// raw: n × 3 counts of the chart photographed under `photographed` (patches in chart.reference.ids order).
SensitivityEstimate estimate_sensitivities(const ChartUnderLamp& photographed, const Eigen::MatrixXd& raw,
                                           const SensitivityPrior& prior);

struct AcrossLampsOptions {
  // Every family, as under the photographed lamp. (Only the five LOO chose on predicted charts — ccm, rootpoly:2–4,
  // rbf:ccm — cost about the same CPU time: the spline's λ search dominated, before it shared one decomposition.)
  std::vector<std::string> methods = all_methods();
  std::vector<FitTarget> targets = {FitTarget::xyz_then_lab, FitTarget::xyz_lightness_weighted, FitTarget::lab_direct};
  CvSpec cv = CvSpec::loo();
  int draws = 40;     // posterior draws propagated to the per-patch uncertainty
  unsigned seed = 1;  // of the draws: a characterization is reproducible
  // A nominal lamp (not measured) is itself uncertain: each draw also draws the lamp (draw_nominal_lamp). Off: the
  // band carries the sensitivities and the family's misfit only (the bench's before/after; docs/ACCURACY.md §6).
  bool nominal_lamp_uncertainty = true;
  SmoothingSearch spline_search = SmoothingSearch::eigen;  // direct: the reference path (bench A/B)
  // What the draws share is computed once: the posterior's decomposition, the chart's resampling (under()), and a
  // spline refit solves for its coefficients only, not its hat matrix (the band uses the model, not its leverages).
  // false: the reference path, as before 2026-11-29 — each draw rebuilds all of it (bench --band-ab 1; the same band
  // to the last digit, AcrossLamps.BandSharingTheDrawsWorkEqualsRebuildingIt).
  bool share_draw_work = true;
};

// One characterization per lamp, named by it.
struct LampCharacterization {
  std::string lamp;
  bool lamp_measured = false;
  std::vector<std::string> warnings;
  std::string method;  // "across-lamps:<lamp>:<chosen family>"
  std::string family;  // the chosen family on the predicted chart ("rbf:ccm", "rootpoly:3", …)
  FitTarget target = FitTarget::xyz_then_lab;
  double parameters = 0;
  ErrorStats cv;                        // cross-validated on the predicted chart
  Characterization model;               // white-balanced RGB under the lamp → L*a*b* (D50)
  std::vector<Characterization> draws;  // the family refitted on charts predicted from posterior draws

  double misfit95 = 0;  // 95th percentile of the cross-validated ΔE00 on the predicted chart

  Eigen::MatrixXd apply(const Eigen::MatrixXd& rgb) const { return model.apply(rgb); }
  // Per row of rgb, the radius (ΔE00 about apply(rgb)) of its 95 % band, two independent parts in quadrature:
  // - the sensitivities' uncertainty and, for a nominal lamp, the lamp's: the 95th percentile over the draws of the
  //   distance to the point prediction;
  // - the family's misfit (which the draws do not contain): misfit95.
  // (A local misfit — the RMS CV error of the 8 nearest training patches — was tried: narrower bands, 84 % pooled
  // coverage against 94 % on four cameras; docs/ACCURACY.md §6.)
  Eigen::VectorXd uncertainty95(const Eigen::MatrixXd& rgb) const;
};

LampCharacterization characterize_across_lamps(const SensitivityEstimate& sensitivities, const ChartUnderLamp& target,
                                               const AcrossLampsOptions& options = {});

}  // namespace colorlab::analysis
