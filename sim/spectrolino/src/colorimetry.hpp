#pragma once
// Colorimetry of the simulated Spectrolino: XYZ, xyY, Lab, LCh(ab) and Luv of the last spectrum under the
// parameters' illuminant and observer (integrators cached per illuminant and observer), and the illuminant
// tables the host can read. Private to sim/spectrolino.
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "colorlab/wire/spectrolino_protocol.hpp"
#include "device_state.hpp"
#include "measurement.hpp"

namespace colorlab::analysis {
class ReflectanceIntegrator;
}

namespace colorlab::sim::spectrolino_detail {

// The colord-data name of an illuminant code ("D50", "F11", "D65" for Dxx 65); nullopt when there is none.
std::optional<std::string> colord_name(sp::Illuminant il, std::uint8_t dxx);

// 38: the table of an illuminant on the instrument's bands, or remote error Illuminant.
sp::IllumTabAnswer illuminant_table(std::uint8_t illuminant, const DeviceSettings& settings);

class Colorimetry {
 public:
  Colorimetry();
  ~Colorimetry();
  // The colour of the last measurement in `type`; adds remote errors to `rem` (NoValidValue with zeros when
  // nothing was measured; nullopt for an unknown illuminant or colour type).
  std::optional<std::array<float, 3>> colour(const LastMeasurement& last, const DeviceSettings& settings,
                                             sp::ColourType type, std::uint16_t& rem);
  // A new user illuminant was downloaded.
  void forget_user_illuminant();

 private:
  std::map<std::pair<int, int>, std::unique_ptr<analysis::ReflectanceIntegrator>> integrators_;
};

}  // namespace colorlab::sim::spectrolino_detail
