#include "colorlab/analysis/standard_data.hpp"

#include <map>
#include <mutex>
#include <string>

#include "colorlab/core/data_paths.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

Observer observer_from_degrees(int degrees) {
  if (degrees == 2) return Observer::cie1931_2deg;
  if (degrees == 10) return Observer::cie1964_10deg;
  throw Error(ErrorClass::bad_parameter, "observer must be 2 or 10 degrees, got " + std::to_string(degrees));
}

SpectralSet load_observer(Observer observer) {
  static std::mutex mu;
  static std::map<Observer, SpectralSet> cache;
  std::lock_guard lock(mu);
  if (auto it = cache.find(observer); it != cache.end()) return it->second;
  const char* file = observer == Observer::cie1931_2deg ? "cmf/CIE1931-2deg-XYZ.cmf" : "cmf/CIE1964-10deg-XYZ.cmf";
  SpectralSet s = read_spectra(paths::colord_file(file));
  if (s.size() != 3) throw Error(ErrorClass::bad_data, std::string(file) + ": expected 3 colour matching functions");
  s.names = {"xbar", "ybar", "zbar"};
  return cache[observer] = s;
}

SpectralSet load_illuminant(std::string_view name) {
  std::string n(name);
  if (n.rfind("CIE-", 0) == 0) n = n.substr(4);
  for (auto& c : n) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (n.empty() || n.find('/') != std::string::npos || n.find('.') != std::string::npos)
    throw Error(ErrorClass::bad_parameter, "illuminant name '" + std::string(name) + "' is not valid");
  auto path = paths::colord_dir() / ("illuminant/CIE-" + n + ".sp");
  if (!std::filesystem::exists(path))
    throw Error(ErrorClass::not_found, "no standard illuminant '" + std::string(name) + "' (looked for " + path.string() + ")",
                "use A, D50, D65, F2, F11 ... or pass a measured spectrum file");
  SpectralSet s = read_spectra(path);
  s.names = {"CIE-" + n};
  validate_emission(s);
  return s;
}

}  // namespace colorlab::analysis
