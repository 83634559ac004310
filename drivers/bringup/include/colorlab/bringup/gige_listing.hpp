#pragma once
// GigE Vision cameras by Aravis: its discovery's list (broadcast on every interface), and cameras
// named by address (the simulated lab's on 127.0.0.1, or a camera on a routed subnet that the
// broadcast does not reach) opened for their identity. Nothing is acquired.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace colorlab::bringup {

nlohmann::json discover_gige_cameras();
// Opens the camera at `address` (an IP or an Aravis device id) and reads vendor, model, serial,
// sensor size and pixel formats. Never throws: a camera that does not answer gets a verdict.
nlohmann::json identify_gige_camera(const std::string& address);

}  // namespace colorlab::bringup
