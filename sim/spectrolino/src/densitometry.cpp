#include "densitometry.hpp"

#include <algorithm>
#include <cmath>

namespace colorlab::sim::spectrolino_detail {

TypedSpectrum typed_spectrum(const std::optional<sp::Spectrum>& last, sp::SpectrumType type) {
  TypedSpectrum t;
  if (last) {
    t.spectrum = *last;
    if (type == sp::SpectrumType::Density) {
      for (auto& v : t.spectrum) v = static_cast<float>(-std::log10(std::max(v, 1e-5f)));
    } else if (type != sp::SpectrumType::Reflectance) {
      t.remote_errors |= sp::remote_err::Spectrum;
    }
  } else {
    t.remote_errors |= sp::remote_err::NoValidValue;
  }
  return t;
}

Densities densities(const std::optional<sp::Spectrum>& last) {
  Densities d;
  d.remote_errors = last ? 0 : sp::remote_err::NoValidValue;
  if (!last) return d;
  const int lo[4] = {400, 600, 500, 400}, hi[4] = {700, 700, 590, 490};
  for (int f = 0; f < 4; ++f) {
    double sum = 0;
    int n = 0;
    for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) {
      int nm = sp::kFirstWavelength + sp::kWavelengthStep * static_cast<int>(i);
      if (nm >= lo[f] && nm <= hi[f]) {
        sum += (*last)[i];
        ++n;
      }
    }
    d.status[static_cast<std::size_t>(f)] = static_cast<float>(-std::log10(std::max(sum / n, 1e-5)));
  }
  for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) {
    float v = static_cast<float>(-std::log10(std::max((*last)[i], 1e-5f)));
    if (v > d.dmax) {
      d.dmax = v;
      d.dmax_nm = static_cast<std::uint16_t>(sp::kFirstWavelength + sp::kWavelengthStep * static_cast<int>(i));
    }
  }
  return d;
}

sp::Bytes density_table_answer(std::uint8_t density_standard) {
  // 3C 00 ds + 4 x 36 floats + rem2: Status-T-like bands (visual, cyan, magenta, yellow).
  sp::Writer w;
  w.u8(sp::ans::DensTabAnswer).u8(0x00).u8(density_standard);
  const double centre[4] = {555, 650, 545, 440}, width[4] = {80, 25, 25, 25};
  for (int f = 0; f < 4; ++f) {
    for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) {
      double nm = sp::kFirstWavelength + sp::kWavelengthStep * static_cast<double>(i);
      w.f32(static_cast<float>(std::exp(-0.5 * std::pow((nm - centre[f]) / width[f], 2))));
    }
  }
  w.u16(0);
  return w.bytes();
}

}  // namespace colorlab::sim::spectrolino_detail
