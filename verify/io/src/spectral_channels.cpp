#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <regex>
#include <string>

#include "colorlab/core/error.hpp"
#include "colorlab/verify/rendering.hpp"

namespace colorlab::verify {

namespace {

// Fichet, Pacanowski & Wilkie (JCGT 10(3), 2021), §3: layer, the band's centre with a comma as decimal separator,
// an optional SI prefix and the unit m or Hz. The layer part is the proposal's `S[0-3]` or the reflective `T`.
const std::regex& band_regex() {
  static const std::regex re(R"(^(S[0-3]|T)\.(\d*,?\d*([Ee][+-]?\d+)?)(Y|Z|E|P|T|G|M|k|h|da|d|c|m|u|n|p)?(m|Hz)$)");
  return re;
}

// The SI prefix as a power of ten (the regex admits only these).
int si_exponent(const std::string& p) {
  static const struct {
    const char* name;
    int exponent;
  } table[] = {{"Y", 24}, {"Z", 21}, {"E", 18}, {"P", 15}, {"T", 12}, {"G", 9}, {"M", 6}, {"k", 3}, {"h", 2}, {"da", 1}, {"d", -1}, {"c", -2}, {"m", -3}, {"u", -6}, {"n", -9}, {"p", -12}};
  for (const auto& e : table)
    if (p == e.name) return e.exponent;
  return 0;
}

// v · 10^e with an exactly representable power of ten, so "S0.450nm" is 450 nm exactly, not 450 · 1e-9 · 1e9.
double times_pow10(double v, int e) {
  double p = 1.0;
  for (int i = 0; i < std::abs(e); ++i) p *= 10.0;
  return e >= 0 ? v * p : v / p;
}

}  // namespace

std::optional<double> spectral_channel_wavelength_nm(const std::string& channel, const std::string& layer) {
  std::smatch m;
  if (!std::regex_match(channel, m, band_regex()) || m[1].str() != layer) return std::nullopt;
  std::string value = m[2].str();
  if (value.empty() || value == ",") return std::nullopt;
  for (auto& c : value)
    if (c == ',') c = '.';
  char* end = nullptr;
  const double v = std::strtod(value.c_str(), &end);
  if (end == value.c_str() || *end != '\0' || !std::isfinite(v) || v <= 0) return std::nullopt;
  const int e = si_exponent(m[4].str());
  if (m[5].str() == "Hz") {
    constexpr double kSpeedOfLight = 299792458.0;  // m/s, exact (SI)
    return kSpeedOfLight / times_pow10(v, e) * 1e9;
  }
  return times_pow10(v, e + 9);
}

std::string spectral_channel_name(double wavelength_nm, bool reflective) {
  if (!(wavelength_nm > 0) || !std::isfinite(wavelength_nm))
    throw Error(ErrorClass::bad_parameter, "a band centre must be a positive wavelength, got " + std::to_string(wavelength_nm));
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f", wavelength_nm);
  std::string v(buf);
  for (auto& c : v)
    if (c == '.') c = ',';
  return std::string(reflective ? "T." : "S0.") + v + "nm";
}

std::vector<double> band_edges_nm(const std::vector<double>& wl) {
  if (wl.size() < 2)
    throw Error(ErrorClass::bad_data, "a spectral rendering needs at least 2 bands to give them widths, got " +
                                          std::to_string(wl.size()));
  for (std::size_t i = 1; i < wl.size(); ++i)
    if (!(wl[i] > wl[i - 1]))
      throw Error(ErrorClass::bad_data, "band centres must increase strictly (band " + std::to_string(i) + ")");
  std::vector<double> edges(wl.size() + 1);
  for (std::size_t i = 1; i < wl.size(); ++i) edges[i] = 0.5 * (wl[i - 1] + wl[i]);
  edges.front() = wl.front() - (edges[1] - wl.front());
  edges.back() = wl.back() + (wl.back() - edges[wl.size() - 1]);
  return edges;
}

}  // namespace colorlab::verify
