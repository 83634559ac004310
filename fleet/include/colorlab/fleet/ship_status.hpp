#pragma once
// What the agent tells its bench: <state_dir>/ship/status.json, rewritten (atomically) after every cycle. colorlabd
// reads it for GET /v1/shipping, `colorlab status` and the console, so the bench shows the agent's last error
// without the daemon ever talking to central or waiting on the network (docs/fleet.md, "Lag").
//
// {"updated_at", "ok" (the last cycle), "position" (central's, as last seen), "last_success_at",
//  "last_cycle": {runs_shipped, measurements, blobs_uploaded}, "last_error": null | {"message", "hint", "at"}}
// last_error stays after a later success (with its time), so a flapping link shows; `ok` says how it is now.
#include <filesystem>
#include <string>

#include "colorlab/fleet/config.hpp"
#include "colorlab/fleet/shipper.hpp"

namespace colorlab::fleet {

inline std::filesystem::path ship_status_file(const ShipConfig& c) { return c.state_dir / "ship" / "status.json"; }

// Never throws: a status that cannot be written must not stop shipping (logged as a warning).
void note_cycle_ok(const ShipConfig& config, const CycleReport& report);
void note_cycle_failed(const ShipConfig& config, const std::string& message, const std::string& hint);

}  // namespace colorlab::fleet
