#include "colorlab/bringup/gige_listing.hpp"

#include <arv.h>

#include <chrono>

namespace colorlab::bringup {

using nlohmann::json;

namespace {

std::string str(const char* s) { return s ? s : ""; }

}  // namespace

json discover_gige_cameras() {
  json out = json::array();
  arv_update_device_list();
  const unsigned n = arv_get_n_devices();
  for (unsigned i = 0; i < n; ++i) {
    std::string protocol = str(arv_get_device_protocol(i));
    out.push_back({
        {"id", str(arv_get_device_id(i))},
        {"vendor", str(arv_get_device_vendor(i))},
        {"model", str(arv_get_device_model(i))},
        {"serial", str(arv_get_device_serial_nbr(i))},
        {"address", str(arv_get_device_address(i))},
        {"protocol", protocol},
    });
  }
  return out;
}

json identify_gige_camera(const std::string& address) {
  const auto start = std::chrono::steady_clock::now();
  json j{{"address", address}};
  GError* err = nullptr;
  // Aravis bounds the open itself: a GVCP discovery to the address, one second, then "not found".
  ArvCamera* cam = arv_camera_new(address.c_str(), &err);
  if (!cam) {
    j["verdict"] = "silent";
    j["message"] = "no GigE Vision camera answered at " + address + (err ? ": " + str(err->message) : std::string());
    j["hint"] = "check the address, the network cable and the camera's power; a camera on another subnet needs a route "
                "(or its IP set with arv-tool-0.8)";
    if (err) g_error_free(err);
  } else {
    auto read = [&](const char* (*f)(ArvCamera*, GError**)) {
      GError* e = nullptr;
      std::string v = str(f(cam, &e));
      if (e) g_error_free(e);
      return v;
    };
    j["verdict"] = "identified";
    j["vendor"] = read(arv_camera_get_vendor_name);
    j["model"] = read(arv_camera_get_model_name);
    j["serial"] = read(arv_camera_get_device_serial_number);
    j["message"] = "a GigE Vision camera answered: " + j["vendor"].get<std::string>() + " " + j["model"].get<std::string>();
    gint w = 0, h = 0;
    GError* e = nullptr;
    arv_camera_get_sensor_size(cam, &w, &h, &e);
    if (!e) {
      j["sensor"] = {w, h};
    } else {
      g_error_free(e);
    }
    e = nullptr;
    guint n = 0;
    const char** formats = arv_camera_dup_available_pixel_formats_as_strings(cam, &n, &e);
    json f = json::array();
    for (guint i = 0; formats && i < n; ++i) f.push_back(str(formats[i]));
    g_free(formats);
    if (e) g_error_free(e);
    j["pixel_formats"] = f;
    j["calibration"] = {
        {"applies", true},
        {"state", "in the daemon"},
        {"detail", "a camera's characterization is a campaign's result (characterize-camera), kept by colorlabd, "
                   "not in the camera"},
    };
    g_object_unref(cam);
  }
  j["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return j;
}

}  // namespace colorlab::bringup
