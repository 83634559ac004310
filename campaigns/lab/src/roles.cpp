#include "colorlab/campaigns/roles.hpp"

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/camera/camera_instrument.hpp"
#include "colorlab/drivers/lab_capabilities.hpp"

namespace colorlab::campaigns {

using drivers::Capability;
namespace cam = drivers::camera;

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

bool is_kind_for(const std::shared_ptr<drivers::Instrument>& i, const std::string& role) {
  if (role == "luminance_meter") return std::dynamic_pointer_cast<drivers::LuminanceMeter>(i) != nullptr;
  if (role == "spectrophotometer") return std::dynamic_pointer_cast<drivers::Spectrometer>(i) != nullptr;
  if (role == "table") return std::dynamic_pointer_cast<drivers::XyTable>(i) != nullptr;
  if (role == "lamps") return std::dynamic_pointer_cast<drivers::LampController>(i) != nullptr;
  if (role == "dimmer") return std::dynamic_pointer_cast<drivers::Dimmer>(i) != nullptr;
  return std::dynamic_pointer_cast<cam::CameraInstrument>(i) != nullptr;
}

bool kind_offers(const std::string& kind, const std::string& role) {
  // The kinds drivers::make_instrument knows, by the roles their drivers serve.
  if (role == "luminance_meter") return kind == "ls110";
  if (role == "spectrophotometer" || role == "table") return kind == "spectrolino";
  if (role == "lamps") return kind == "dmx" || kind == "hidrelay";
  if (role == "dimmer") return kind == "dmx";
  return kind == "genicam" || kind == "gphoto2" || kind == "simdslr";
}

std::string absent_for(const InstrumentSet& instruments, const std::string& role) {
  std::string out;
  auto note = [&](const std::string& id, const std::string& reason) {
    out += (out.empty() ? "" : "; ") + ("'" + id + "' is configured but absent: " + reason);
  };
  for (const auto& i : instruments.all()) {
    if (!is_kind_for(i, role)) continue;
    if (auto reason = InstrumentSet::absence(*i)) note(i->id(), *reason);
  }
  for (const auto& a : instruments.absent()) {
    if (kind_offers(a.kind, role)) note(a.id, a.reason);
  }
  return out;
}

void refuse_role(const InstrumentSet& instruments, const std::string& role) {
  auto absent = absent_for(instruments, role);
  if (absent.empty()) {
    throw Error(ErrorClass::not_found, "this campaign needs " + role_words(role) + ", and none is configured",
                "add one to colorlabd's configuration, or run the simulated lab");
  }
  throw Error(ErrorClass::not_found, "this campaign needs " + role_words(role) + ", and it is not here: " + absent,
              "`colorlab instruments` lists it with its reason; put that right (plug it in, or fix its entry and "
              "restart colorlabd), then start the campaign again");
}

std::shared_ptr<cam::CameraInstrument> select_camera(const InstrumentSet& instruments, const nlohmann::json& id_or_kind) {
  if (!id_or_kind.is_string() || id_or_kind.get<std::string>().empty()) {
    throw Error(ErrorClass::bad_parameter, "lab.camera.photograph_chart: camera must be an instrument id or a kind (dslr, genicam)");
  }
  const std::string want = id_or_kind.get<std::string>();
  if (auto i = instruments.find(want)) {
    if (auto c = std::dynamic_pointer_cast<cam::CameraInstrument>(i)) return c;
    throw Error(ErrorClass::bad_parameter, "instrument '" + want + "' is not a camera", "name a camera's id or kind");
  }
  std::string cameras;
  for (const auto& i : instruments.all()) {
    auto c = std::dynamic_pointer_cast<cam::CameraInstrument>(i);
    if (!c) continue;
    if (cam::to_string(c->camera().identity().kind) == want) return c;
    cameras += (cameras.empty() ? "" : ", ") + c->id() + " (" + std::string(cam::to_string(c->camera().identity().kind)) + ")";
  }
  throw Error(ErrorClass::not_found, "no camera has the id or kind '" + want + "'",
              cameras.empty() ? "add a camera to colorlabd's configuration, or run the simulated lab"
                              : "the configured cameras are " + cameras);
}

}  // namespace colorlab::campaigns
