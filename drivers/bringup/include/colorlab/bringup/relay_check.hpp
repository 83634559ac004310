#pragma once
// A dcttech USB HID relay board identified by its own state report (GET_REPORT feature: the 5-char
// board id and the relay mask, instrument-protocols §3b) through the relay driver's connect, which
// switches nothing. `where` is a hidraw path (hidapi) or "unix:PATH" (the simulated lab's board).
#include <string>

#include <nlohmann/json.hpp>

namespace colorlab::bringup {

// Never throws: a board that does not answer gets a verdict and the driver's reason.
nlohmann::json identify_relay(const std::string& where);

}  // namespace colorlab::bringup
