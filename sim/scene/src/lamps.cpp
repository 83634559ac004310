#include "lamps.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>

#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::sim {

std::string_view to_string(Lamp lamp) {
  switch (lamp) {
    case Lamp::d65: return "D65";
    case Lamp::tl84: return "TL84";
    case Lamp::cwf: return "CWF";
    case Lamp::a: return "A";
    case Lamp::uv: return "UV";
  }
  return "?";
}

Lamp lamp_from_string(std::string_view name) {
  std::string up;
  for (char c : name) up.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
  if (up == "D65") return Lamp::d65;
  if (up == "TL84" || up == "F11" || up == "840") return Lamp::tl84;
  if (up == "CWF" || up == "F2") return Lamp::cwf;
  if (up == "A") return Lamp::a;
  if (up == "UV") return Lamp::uv;
  throw Error(ErrorClass::bad_parameter, "unknown lamp \"" + std::string(name) + "\"",
              "use one of D65, TL84 (F11, 840), CWF (F2), A, UV");
}

namespace detail {
namespace {

Spectrum to_spectrum(const analysis::SpectralSet& set, Eigen::Index row) {
  // colord's tables are on uniform 5 nm grids.
  const auto& wl = set.wavelengths;
  if (wl.size() < 2) throw Error(ErrorClass::bad_data, set.source + ": spectrum has fewer than two samples");
  Spectrum out{wl.front(), wl[1] - wl[0], std::vector<double>(wl.size())};
  for (std::size_t i = 0; i < wl.size(); ++i) {
    if (std::abs(wl[i] - out.wavelength(i)) > 1e-6)
      throw Error(ErrorClass::bad_data, set.source + ": wavelength grid is not uniform");
    out.values[i] = set.values(row, static_cast<Eigen::Index>(i));
  }
  return out;
}

void normalise_peak(Spectrum& s) {
  const double peak = *std::max_element(s.values.begin(), s.values.end());
  for (double& v : s.values) v /= peak;
}

// A blacklight-blue tube: the mercury-phosphor band around 368 nm plus the weak 405/436 nm lines that
// leak through the Wood's-glass envelope (which is what makes it faintly visible).
Spectrum uv_band() {
  Spectrum s{300.0, 5.0, std::vector<double>(107)};
  for (std::size_t i = 0; i < s.values.size(); ++i) {
    const double nm = s.wavelength(i);
    const double band = std::exp(-0.5 * std::pow((nm - 368.0) / 9.0, 2));
    const double lines = 0.06 * std::exp(-0.5 * std::pow((nm - 405.0) / 2.5, 2)) +
                         0.04 * std::exp(-0.5 * std::pow((nm - 436.0) / 2.5, 2));
    s.values[i] = band + lines;
  }
  return s;
}

}  // namespace

Spectrum load_lamp_spectrum(Lamp lamp) {
  const char* name = nullptr;
  switch (lamp) {
    case Lamp::d65: name = "D65"; break;
    case Lamp::tl84: name = "F11"; break;
    case Lamp::cwf: name = "F2"; break;
    case Lamp::a: name = "A"; break;
    case Lamp::uv: return uv_band();
  }
  Spectrum s = to_spectrum(analysis::load_illuminant(name), 0);
  normalise_peak(s);
  return s;
}

Spectrum load_y_bar() {
  const auto observer = analysis::load_observer(analysis::Observer::cie1931_2deg);
  return to_spectrum(observer, static_cast<Eigen::Index>(observer.require("ybar")));
}

double photopic_integral(const Spectrum& s, const Spectrum& y_bar) {
  double sum = 0.0;
  for (std::size_t i = 0; i < s.values.size(); ++i) sum += s.values[i] * y_bar.at(s.wavelength(i));
  return sum * s.step_nm;
}

}  // namespace detail
}  // namespace colorlab::sim
