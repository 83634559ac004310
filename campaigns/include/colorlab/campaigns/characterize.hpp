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
// §7.4's black box predicts counts from spectra, not colours from counts; it needs the lamp's
// spectrum as well and is not among these yet.
#include <nlohmann/json.hpp>

namespace colorlab::campaigns {

// camera: {ids, values = [[r, g, b], …], format, bits} (one format of lab.camera.photograph_chart);
// reference: {ids, Lab, XYZ} (lab.runs.chart_reference); patches are matched by id.
// options: {cv = "loo" | "k10" …, tolerance_de00 = 0.1, colour_space = "adobe_rgb" | "srgb",
// profile_gamma = 1 (raw) or 2.2 (processed), exclude = {ids}}.
// Returns {format, patches, cv, approaches = {<name> = {training, cv (each {mean, median, p95, max,
// mean_de76}), …}}, best_approach, selected = {approach, method, target, terms, coefficients, …}}.
// Throws Error(bad_data) for mismatched or too few patches, Error(bad_parameter) for options.
nlohmann::json characterize(const nlohmann::json& camera, const nlohmann::json& reference, const nlohmann::json& options);

}  // namespace colorlab::campaigns
