#pragma once
// The lab's stored lens calibrations as the daemon serves them (GET /v1/lab/lenses), for `colorlab scene` and
// `colorlab verify`. A daemon that does not serve the route — one older than it, or a fleet's central API — answers
// 404; that is not the lab saying it has no lens, so the caller falls back as it does for none and says why
// (kNoLensRoute). Every other refusal stays an error: a 401 or 403 is a key to fix, a 5xx a daemon to look at, and a
// wrong answer must not pass for "no calibration".
#include <optional>
#include <vector>

#include "colorlab/client/api_client.hpp"
#include "colorlab/verify/lens_calibration.hpp"

namespace colorlab::cli {

// Why no calibration was consulted, in the words `placement.light.how` and `lens_calibrations` carry.
inline constexpr const char* kNoLensRoute = "the daemon serves no lens calibrations (GET /v1/lab/lenses: 404)";

// nullopt for a 404; client::ApiError for any other refusal; Error{protocol_error} for a body that is not JSON,
// Error{bad_data} for one without `items` or with a calibration lens_from_json refuses.
std::optional<std::vector<verify::LensCalibration>> daemon_lenses(const client::ApiClient& api);

}  // namespace colorlab::cli
