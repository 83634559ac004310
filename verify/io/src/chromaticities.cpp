#include "colorlab/verify/rendering.hpp"

namespace colorlab::verify {

// ITU-R BT.709: what OpenEXR's ImfChromaticities defaults to.
Chromaticities rec709_chromaticities() { return {{{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}, {0.3127, 0.3290}}}; }

// Radiance's STDPRIMS (src/common/color.h): CCIR 709 red and blue, a green of 0.29/0.60 and the equal-energy white.
Chromaticities radiance_chromaticities() {
  return {{{0.640, 0.330}, {0.290, 0.600}, {0.150, 0.060}, {1.0 / 3.0, 1.0 / 3.0}}};
}

}  // namespace colorlab::verify
