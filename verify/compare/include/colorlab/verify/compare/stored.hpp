#pragma once
// A verification stored like a run (issue 23): campaign "verify", its parameters (the rendering, the runs it was
// checked against, the scale), one measurement row per comparison and the summary as the run's summary — so the
// store, GET /v1/runs/{id} and its measurements, export and the report read it as they read any run, and a query
// by step prefix ("colour_7_3/", "light_spot/") gives one kind.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/core/step_records.hpp"
#include "colorlab/verify/compare/verification.hpp"

namespace colorlab::verify {

inline constexpr const char* kVerifyCampaign = "verify";

// How the rendering's noise level was pooled over a region's neighbours, in a stored verification's params
// (`noise_pooling`): today's engine screens each region against its neighbours' median first (docs/verify.md "The
// uncertainty, source by source"). Verifications stored before the field have none, and read back as null: those
// made before 2026-11-29's robust screen pooled with plain sums, later ones with the screen, and the row cannot say
// which.
inline constexpr const char* kNoisePooling = "median-screen";

struct StoredVerification {
  nlohmann::json params;                           // {rendering, against: [run ids], scale (null: fitted), k, rendering_noise, noise_neighbours, noise_pooling[, placement]}
  nlohmann::json summary;                          // Verification::summary() plus floor_difference
  std::vector<records::Measurement> measurements;  // step "<kind>/<where>", value = the difference
};

// What a verification was made with, as a stored verification's params and POST /v1/verifications' body carry it
// (the body adds `result`): {rendering, against, scale (null: fitted), k, rendering_noise, noise_neighbours and
// noise_pooling (both null when the rendering's noise is off)[, placement]}.
nlohmann::json verification_params(const std::string& rendering, const std::vector<std::string>& against,
                                   const CompareOptions& options, const nlohmann::json& placement = nullptr);

// A stored verification's params as they read back (GET /v1/runs/{id}): one stored before `noise_pooling` existed
// gets it as null (not recorded), so every verification's params have the same keys.
nlohmann::json params_read_back(nlohmann::json params);

// `placement`: how the comparison placed the measurement in the rendering (the CLI's `placement`: the floor through
// the lens calibration or as a pinhole), kept in params when given so the stored verification says which.
StoredVerification to_store(const Verification& v, const std::string& rendering, const std::vector<std::string>& against,
                            const CompareOptions& options, const nlohmann::json& placement = nullptr);

// The exit status a renderer's CI gates on: 0 every comparison agrees, 4 some differ beyond the measurement's
// uncertainty. colorlab's other codes keep their meaning (docs/ARCHITECTURE.md: 1 local error, 2 API refused), so a
// verification that could not be made is never read as a verdict.
inline constexpr int kExitAgrees = 0;
inline constexpr int kExitDiffers = 4;
int exit_status(const Verification& v);

}  // namespace colorlab::verify
