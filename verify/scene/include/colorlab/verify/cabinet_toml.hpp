#pragma once
// The lab configuration's [cabinet] table (docs/verify.md "The measured scene"): read by colorlab-sim's lab
// file and by `colorlab scene --lab FILE`. Unknown keys and bad values are errors naming file and line.
#include <filesystem>

#include <toml++/toml.h>

#include "colorlab/verify/cabinet.hpp"

namespace colorlab::verify {

// The [cabinet] table's contents over the defaults; [[cabinet.emitter]] entries, when any, replace the
// default emitters. Validated. Throws Error(bad_parameter) "file:line: what".
CabinetGeometry cabinet_from_toml(const toml::table& cabinet, const std::filesystem::path& file);

// The [cabinet] table of a TOML file (default_cabinet() when the file has none).
CabinetGeometry cabinet_from_file(const std::filesystem::path& file);

}  // namespace colorlab::verify
