#pragma once
// The cabinet as JSON, in the [cabinet] table's own keys and units (mm): what colorlabd serves at
// GET /v1/lab/cabinet and `colorlab scene` reads back when no --lab file is given (docs/verify.md).
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/verify/cabinet.hpp"

namespace colorlab::verify {

// {width_mm, depth_mm, height_mm, floor_reflectance, chart_center_mm: [x, y], grid_pitch_mm: [x, y],
//  emitter: [{lamp, center_mm, size_mm, luminance_cd_m2}]}
nlohmann::json cabinet_to_json(const CabinetGeometry& cabinet);

// The inverse, validated like the TOML table. Error(bad_data) naming `where` and the field for anything missing,
// mistyped or outside its range (a daemon of another version, a hand-made answer).
CabinetGeometry cabinet_from_json(const nlohmann::json& j, const std::string& where);

}  // namespace colorlab::verify
