#pragma once
// The ColorChecker SG: its geometry and where its spectra come from.
#include "colorlab/sim/scene.hpp"

namespace colorlab::sim::detail {

// Spectra from a CSV (wavelength_nm, A1..N10 columns) or CGATS (SAMPLE_ID + SPEC_nnn) file, resampled to
// 380–730/10 nm. Throws Error(bad_data) naming the file for missing patches or a bad wavelength grid.
Chart chart_from_file(const std::filesystem::path& path);

// 140 smooth, plausible spectra (neutral border and grey ramp, saturated and skin-like colours),
// the same for every scene seed.
Chart synthetic_chart();

// Config's chart_file, else the shared data set's pre-2014 X-Rite spectra when present, else synthetic.
Chart load_chart(const SceneConfig& config);

}  // namespace colorlab::sim::detail
