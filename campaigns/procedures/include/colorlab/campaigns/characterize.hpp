#pragma once
// lab.analysis.characterize: chapter 7's approaches fitted to one photograph's patch values against a
// chart read's reference colours, each with its training and cross-validated colour differences, and
// the model that selection chooses, in JSON that can be stored with the run and applied again.
//
//   (a) camera_colour_space  the camera's own encoding (Adobe RGB 1998 by default) read as such
//                            (§7.1; processed formats only: a raw has no colour space). Nothing is
//                            fitted, so its cross-validated error is its training error.
//   (b) icc_profile          a matrix/shaper input profile built from the chart with lcms2 (§7.2),
//                            cross-validated by refitting it without the held-out patches.
//   (c) adapted_mapping      every polynomial term set and spline, every target, cross-validated,
//                            smallest model within tolerance of the best (§7.3, select_method).
//   (d) black_box            §7.4, raw only: the camera's spectral sensitivities fitted (NNLS) to the
//                            raw counts from the reference's reflectance spectra lit by the lamp's
//                            standard spectrum (D65, A, TL84 = CIE F11, CWF = CIE F2 from colord-data;
//                            assumed, not measured, and said so in the result), under a prior from
//                            the shared data set's camspec cameras when present (with 95 % credible
//                            bands), else a GCV smoothness penalty. Its counts go through (c)'s
//                            selected method to L*a*b*; cross-validated by refitting both without
//                            the held-out patches. Also Table 13's count residuals (% of full scale).
#include <nlohmann/json.hpp>

namespace colorlab::campaigns {

// camera: {ids, values = [[r, g, b], …], format, bits} (one format of lab.camera.photograph_chart);
// reference: {ids, Lab, XYZ} (lab.runs.chart_reference); patches are matched by id.
// reference: {ids, Lab, XYZ, wavelengths, spectra} (lab.runs.chart_reference; spectra only for (d)).
// options: {cv = "loo" | "k10" …, tolerance_de00 = 0.1, colour_space = "adobe_rgb" | "srgb",
// profile_gamma = 1 (raw) or 2.2 (processed), exclude = {ids}, lamp = "D65" (the cabinet lamp the
// chart was photographed under) or illuminant = "F11" (any colord illuminant), prior = "camspec" |
// "none", prior_exclude = {camspec camera names, e.g. "Canon_20D"}}.
// Returns {format, patches, cv, approaches = {<name> = {training, cv (each {mean, median, p95, max,
// mean_de76}), …}}, best_approach, selected = {approach, method, target, terms, coefficients, …},
// not_fitted = {black_box = why, for a raw without spectra or a known lamp}}.
// Throws Error(bad_data) for mismatched or too few patches, Error(bad_parameter) for options.
nlohmann::json characterize(const nlohmann::json& camera, const nlohmann::json& reference, const nlohmann::json& options);

// (d) alone, with the mapping to L*a*b* given: options as above plus mapping = {method, target}
// (e.g. a run's selected model, to hold the black box to a simulator's truth). Throws
// Error(bad_parameter) when the black box cannot be fitted (not a raw, no spectra, no known lamp).
nlohmann::json characterize_black_box(const nlohmann::json& camera, const nlohmann::json& reference,
                                      const nlohmann::json& options);

}  // namespace colorlab::campaigns
