#include "colorlab/drivers/lab_capabilities.hpp"

namespace colorlab::drivers {

std::string_view to_string(SpectralMode m) {
  switch (m) {
    case SpectralMode::reflectance: return "reflectance";
    case SpectralMode::emission: return "emission";
    case SpectralMode::transmission: return "transmission";
  }
  return "reflectance";
}

}  // namespace colorlab::drivers
