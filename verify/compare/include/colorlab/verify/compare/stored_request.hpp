#pragma once
// POST /v1/verifications' body read back into a stored verification (docs/API.md): the comparison is made where the
// rendering is (the CLI, the Python client), and the daemon stores its result like a run. The body is
//   {"rendering": name, "against": [run ids], "scale": number|null, "k": number, "result": Verification::to_json(),
//    "rendering_noise": bool (optional, default true), "noise_neighbours": integer ≥ 1 | null (optional, default 8),
//    "placement": {...} (optional: how the light was placed in the rendering, kept in the run's params)}
// and the summary is recomputed here from the comparisons, so a stored verdict always matches its rows.
#include <nlohmann/json.hpp>

#include "colorlab/verify/compare/stored.hpp"

namespace colorlab::verify {

// Verification::to_json()'s inverse (comparisons, scales, floor_difference). Error(bad_parameter) naming the field
// for anything missing or mistyped, and for a verdict that contradicts its own distance and threshold.
Verification verification_from_json(const nlohmann::json& result);

// The whole request body → what store_verification writes. Error(bad_parameter) as above.
StoredVerification stored_from_request(const nlohmann::json& body);

// The request body for a verification made here (the inverse of stored_from_request).
nlohmann::json store_request(const Verification& v, const std::string& rendering, const std::vector<std::string>& against,
                             const CompareOptions& options, const nlohmann::json& placement = nullptr);

}  // namespace colorlab::verify
