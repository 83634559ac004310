#pragma once
// The roles a campaign names its instruments by ("luminance_meter", "table", …) and the
// capability that offers each: one table for the live lab and the dry run.
#include <string>

#include "colorlab/drivers/instrument.hpp"

namespace colorlab::campaigns {

// Error{internal} for a role no lab call names.
drivers::Capability capability_of(const std::string& role);
// "a luminance meter (LS-110)": for messages to a person.
std::string role_words(const std::string& role);

}  // namespace colorlab::campaigns
