#pragma once
// lab.analysis.characterize's characterizations for lamps other than the one the chart was photographed under
// (issue 26; analysis/relighting.hpp): the camera's sensitivities estimated from the raw, the chart predicted under
// each target lamp from them and the chart-read's spectra, every family selected on that prediction, and a per-patch
// 95 % band from the sensitivities' posterior. One characterization per lamp, named by it; a lamp whose spectrum is a
// nominal CIE standard (no measured spectrum given) carries a warning.
#include <nlohmann/json.hpp>

#include "colorlab/analysis/regression.hpp"

namespace colorlab::campaigns {

// d: the matched patches (raw counts, reference); reference: {ids, wavelengths, spectra, …};
// options: {lamp = the photographed lamp, target_lamps = ["TL84", "A", …],
//           lamp_spectra = {<lamp> = {wavelengths = [...], values = [...]}} (measured; else the nominal standard),
//           prior_exclude = {camspec names}, draws = 40}.
// Returns {<lamp> = {lamp, lamp_measured, warnings, method, family, target, parameters, cv, uncertainty95 = {ids,
// de00}, input, model}} for every target lamp other than the photographed one, or {} when there are none.
// Throws Error(bad_parameter) for a raw without spectra, an unknown lamp or a missing prior.
nlohmann::json characterize_across_lamps(const analysis::ChartData& d, const nlohmann::json& reference, const nlohmann::json& options);

}  // namespace colorlab::campaigns
