#pragma once
// CIE standard observers and illuminants, read at run time from Debian's colord-data.
#include <string_view>

#include "colorlab/analysis/spectral.hpp"

namespace colorlab::analysis {

enum class Observer {
  cie1931_2deg,
  cie1964_10deg
};

Observer observer_from_degrees(int degrees);  // 2 or 10; throws Error(bad_parameter)
// Three rows named xbar, ybar, zbar.
SpectralSet load_observer(Observer observer);
// "A", "D50", "D65", "F2", "F11", ... (also "CIE-F11"); one row. Throws Error(not_found) for unknown names.
SpectralSet load_illuminant(std::string_view name);

}  // namespace colorlab::analysis
