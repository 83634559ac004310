#pragma once
// Densitometry and spectrum types of the simulated Spectrolino: the last spectrum as reflectance or density,
// the four status densities (visual, cyan, magenta, yellow) and Dmax, and the density filter table the host can
// read. Private to sim/spectrolino.
#include <array>
#include <cstdint>
#include <optional>

#include "colorlab/wire/spectrolino_protocol.hpp"

namespace colorlab::sim::spectrolino_detail {

namespace sp = wire::spectrolino;

// The last spectrum in `type` (reflectance or density) with its remote errors (NoValidValue when there is no
// measurement, Spectrum for another type).
struct TypedSpectrum {
  sp::Spectrum spectrum{};
  std::uint16_t remote_errors = 0;
};
TypedSpectrum typed_spectrum(const std::optional<sp::Spectrum>& last, sp::SpectrumType type);

// Densities of the last spectrum: mean reflectance over each filter's band, and the densest band.
struct Densities {
  std::array<float, 4> status{};  // visual, cyan (red light), magenta (green), yellow (blue)
  float dmax = 0;
  std::uint16_t dmax_nm = 0;
  std::uint16_t remote_errors = 0;
};
Densities densities(const std::optional<sp::Spectrum>& last);

// 3B: the density filter table (Status-T-like bands) as the 3C answer body.
sp::Bytes density_table_answer(std::uint8_t density_standard);

}  // namespace colorlab::sim::spectrolino_detail
