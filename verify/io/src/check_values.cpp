#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "io_detail.hpp"

namespace colorlab::verify::detail {

void check_values(const Rendering& image, const std::filesystem::path& file, const std::vector<std::string>& names) {
  // Out-of-gamut colours are negative in RGB; light and reflectance never are.
  const bool negatives_allowed = image.encoding == Encoding::rgb;
  const float lo = negatives_allowed ? -std::numeric_limits<float>::max() : 0.0f;
  const float hi = std::numeric_limits<float>::max();
  const float* p = image.pixels.data();
  const std::size_t n = image.pixels.size();
  // One branch-free pass first (it vectorises); the slow search for where runs only on a bad file.
  bool ok = true;
  for (std::size_t i = 0; i < n; ++i) ok &= (p[i] >= lo) & (p[i] <= hi);
  if (ok) return;
  std::size_t first = n, count = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!(p[i] >= lo && p[i] <= hi)) {
      if (first == n) first = i;
      ++count;
    }
  const std::size_t c = static_cast<std::size_t>(image.channels());
  const std::size_t pixel = first / c;
  const std::size_t x = pixel % static_cast<std::size_t>(image.width), y = pixel / static_cast<std::size_t>(image.width);
  const float v = p[first];
  const std::string kind = std::isnan(v) ? "NaN" : std::isinf(v) ? (v > 0 ? "+inf" : "-inf")
                                                                 : "negative value " + std::to_string(v);
  const std::string channel = first % c < names.size() ? names[first % c] : "#" + std::to_string(first % c);
  bad_data(file,
           kind + " at pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") channel " + channel + " (" +
               std::to_string(count) + " value(s) out of range in the image)",
           negatives_allowed ? "a renderer's image must be finite everywhere; fix or mask the pixels before verifying"
                             : "spectral radiance, reflectance and XYZ are finite and non-negative; a reconstruction "
                               "filter with negative lobes or a denoiser can produce this: render without them");
}

}  // namespace colorlab::verify::detail
