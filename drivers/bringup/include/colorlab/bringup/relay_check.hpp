#pragma once
// A dcttech USB HID relay board identified by its own state report (GET_REPORT feature: the 5-char
// board id and the relay mask, instrument-protocols §3b) through the relay driver's connect, which
// switches nothing. `where` is a hidraw path (hidapi) or "unix:PATH" (the simulated lab's board).
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/bringup/recording.hpp"
#include "colorlab/wire/hid_transport.hpp"

namespace colorlab::bringup {

// Never throws: a board that does not answer gets a verdict and the driver's reason. With a
// `recording`, every feature report exchanged is recorded into it (hid_recording.hpp). The answer's
// "hid" holds what the transport said of the device (the product string sets the relay count), which
// a transcript's header keeps for its replay.
nlohmann::json identify_relay(const std::string& where, Recording* recording = nullptr);
// The same on a transport already made (a replayed transcript's); `where` only names it.
nlohmann::json identify_relay(std::unique_ptr<drivers::HidTransport> transport, const std::string& where);

}  // namespace colorlab::bringup
