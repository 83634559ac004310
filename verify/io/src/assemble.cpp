#include <cmath>

#include "colorlab/core/error.hpp"
#include "io_detail.hpp"

namespace colorlab::verify {

Rendering assemble_spectral(const std::vector<Rendering>& bands, const std::vector<double>& wavelengths_nm,
                            const std::string& units) {
  if (bands.empty() || bands.size() != wavelengths_nm.size())
    throw Error(ErrorClass::bad_parameter, "assembling a spectral rendering needs one image per band: " +
                                               std::to_string(bands.size()) + " images for " +
                                               std::to_string(wavelengths_nm.size()) + " band centres");
  for (std::size_t i = 0; i < wavelengths_nm.size(); ++i)
    if (!(wavelengths_nm[i] > 0) || (i > 0 && !(wavelengths_nm[i] > wavelengths_nm[i - 1])))
      throw Error(ErrorClass::bad_parameter, "band centres must be positive and increase strictly (band " + std::to_string(i) + ")");
  Rendering r;
  r.encoding = Encoding::spectral;
  r.width = bands.front().width;
  r.height = bands.front().height;
  r.wavelengths_nm = wavelengths_nm;
  r.units = units;
  r.source_format = "assembled-bands";
  const std::size_t n = static_cast<std::size_t>(r.width) * static_cast<std::size_t>(r.height);
  const std::size_t nb = bands.size();
  r.pixels.assign(n * nb, 0.0f);
  for (std::size_t b = 0; b < nb; ++b) {
    const Rendering& im = bands[b];
    const std::size_t c = static_cast<std::size_t>(im.channels());
    if (im.width != r.width || im.height != r.height || im.pixels.size() != n * c)
      throw Error(ErrorClass::bad_data, "band " + std::to_string(b) + " (" + std::to_string(wavelengths_nm[b]) + " nm) is " + std::to_string(im.width) + " x " + std::to_string(im.height) + ", band 0 is " + std::to_string(r.width) + " x " + std::to_string(r.height),
                  "render every band at the same resolution");
    // A band rendered with grey albedos and a grey light has R = G = B; the mean keeps what the renderer's colour
    // handling would do to them out of the band's value.
    for (std::size_t p = 0; p < n; ++p) {
      double s = 0;
      for (std::size_t k = 0; k < c; ++k) s += im.pixels[p * c + k];
      r.pixels[p * nb + b] = static_cast<float>(s / static_cast<double>(c));
    }
  }
  std::vector<std::string> names;
  for (double nm : wavelengths_nm) names.push_back(spectral_channel_name(nm));
  detail::check_values(r, "assembled bands", names);
  return r;
}

}  // namespace colorlab::verify
