#pragma once
// A measurement page's JSON written straight into one string, byte for byte what the bench's
// MeasurementRecord::to_json documents dump to (members in name order, nlohmann's escaping and number forms), without
// building a JSON tree of every measurement first: on a 500-measurement page that tree was most of central's work.
#include <optional>
#include <string>

#include "colorlab/store/store.hpp"

namespace colorlab::fleet {

// {"items":[...],"links":{"next":<next_link>},"next_cursor":<next_cursor>}, null for a missing one.
std::string measurement_page_json(const store::MeasurementPage& page, const std::optional<std::string>& next_cursor,
                                  const std::optional<std::string>& next_link);

}  // namespace colorlab::fleet
