#pragma once
// The roles a campaign names its instruments by ("luminance_meter", "table", …) and the
// capability that offers each: one table for the live lab and the dry run.
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/campaigns/instrument_set.hpp"
#include "colorlab/drivers/instrument.hpp"

namespace colorlab::drivers::camera {
class CameraInstrument;
}

namespace colorlab::campaigns {

// Error{internal} for a role no lab call names.
drivers::Capability capability_of(const std::string& role);
// "a luminance meter (LS-110)": for messages to a person.
std::string role_words(const std::string& role);

// Whether the instrument is of the C++ kind that serves `role` (it may learn the capability only
// once connected, as a Spectrolino learns whether it sits on a table).
bool is_kind_for(const std::shared_ptr<drivers::Instrument>& i, const std::string& role);
// Whether a configured kind ("ls110", "genicam", …) would serve `role` once it is up.
bool kind_offers(const std::string& kind, const std::string& role);
// "'genicam' is configured but absent: REASON" for every absent instrument that would serve
// `role` ("; "-joined), or "" when none is: the refusal then says why, not just "none".
std::string absent_for(const InstrumentSet& instruments, const std::string& role);
// Error{not_found}: the campaign needs `role` and no instrument can serve it now.
[[noreturn]] void refuse_role(const InstrumentSet& instruments, const std::string& role);

// The camera an options table names by instrument id ("dslr") or by kind ("dslr", "genicam");
// Error(not_found) listing the cameras there are, Error(bad_parameter) for a non-camera id.
std::shared_ptr<drivers::camera::CameraInstrument> select_camera(const InstrumentSet& instruments,
                                                                 const nlohmann::json& id_or_kind);

}  // namespace colorlab::campaigns
