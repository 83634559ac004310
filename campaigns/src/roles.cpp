#include "roles.hpp"

#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

using drivers::Capability;

Capability capability_of(const std::string& role) {
  if (role == "luminance_meter") return Capability::luminance;
  if (role == "spectrophotometer") return Capability::reflectance_spectrum;
  if (role == "table") return Capability::xy_table;
  if (role == "lamps") return Capability::lamp_switching;
  if (role == "dimmer") return Capability::dimmer;
  if (role == "camera") return Capability::camera;
  throw Error(ErrorClass::internal, "unknown role " + role);
}

std::string role_words(const std::string& role) {
  if (role == "luminance_meter") return "a luminance meter (LS-110)";
  if (role == "spectrophotometer") return "a spectrophotometer (Spectrolino)";
  if (role == "table") return "an XY table (SpectroScan T)";
  if (role == "lamps") return "lamp switching (DMX widget or relay board)";
  if (role == "dimmer") return "a dimmer (DMX widget)";
  return "a camera";
}

}  // namespace colorlab::campaigns
