#pragma once
// The light half of a MeasuredScene read from stored runs (issue 23): a cabinet-grid run's LS-110 spots and a
// floor-luminance run's map, from their measurement rows as the store and GET /v1/runs/{id}/measurements give
// them ({step, quantity, value, unit, data}). Where each spot lies in the rendering comes from the caller (the
// exported scene's floor homography), not from the runs.
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/verify/compare/verification.hpp"

namespace colorlab::verify {

struct LightSelection {
  std::string lamp = "D65";
  double dimmer_percent = 100;
};

using SpotRegion = std::function<PixelRect(int row, int col)>;

// One LS-110 reading's standard deviation when a run has no repeated readings to pool: docs/campaigns.md puts the
// LS-110's repeatability at 4 σ of the difference of two readings ≈ 0.6 %.
inline constexpr double kLs110RelativeSd = 0.006 / (4 * 1.4142135623730951);
// The drift a lamp accepted as stable may still show over a run (docs/campaigns.md, "a lamp that drifts": ≤ 1 %).
inline constexpr double kLampDriftBound = 0.01;

// Spots `L/<lamp>/D<level>/r<row>c<col>`: the mean of `data.readings`, and one reading's standard deviation pooled
// over every spot with two or more readings (relative), else kLs110RelativeSd. Sets the drift bound when unset.
// Throws Error(not_found) when the run has no reading for that lamp and level.
void add_cabinet_grid(MeasuredScene& scene, const std::vector<nlohmann::json>& measurements, const LightSelection& which,
                      const SpotRegion& region);

// Cells `F/<lamp>/D<level>/r<row>c<col>`, each with the relative RMS of the flat field's calibration residuals
// (`P/<lamp>/D<level>`'s `data.calibration[].residual_pct`) as its standard uncertainty. Throws Error(not_found)
// without cells, Error(bad_data) when the fit has no residual to judge it by (as many calibration spots as terms).
void add_floor_luminance(MeasuredScene& scene, const std::vector<nlohmann::json>& measurements,
                         const LightSelection& which, const SpotRegion& region);

}  // namespace colorlab::verify
