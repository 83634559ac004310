#pragma once
// Measurement synthesis for the simulated Spectrolino: the Scene's spectra on the instrument's 36 bands
// (380..730 nm), what lies under the head, and the last measured spectrum. Private to sim/spectrolino.
#include <cstdint>
#include <optional>
#include <vector>

#include "colorlab/sim/spectrum.hpp"
#include "colorlab/wire/spectrolino_protocol.hpp"

namespace colorlab::sim::spectrolino_detail {

namespace sp = wire::spectrolino;

inline constexpr double kAirReflectance = 0.002;  // head raised: stray light only

// A Scene spectrum resampled onto the instrument's bands, and back.
sp::Spectrum to_bands(const Spectrum& s);
Spectrum from_bands(const sp::Spectrum& b);
sp::Spectrum flat(float v);
// The instrument's wavelengths, 380..730 nm in 10 nm steps.
std::vector<double> band_grid();

// The last measurement (what 05/06/03/04/B8/BA/BD answer from).
struct LastMeasurement {
  std::optional<sp::Spectrum> spectrum;
  std::uint8_t mode = sp::ctt::ModeReflectance;  // the mode it was measured in
  std::uint64_t count = 0;                       // measurements made since construction
};

}  // namespace colorlab::sim::spectrolino_detail
