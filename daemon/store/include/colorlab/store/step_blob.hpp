#pragma once
// A blob a campaign step kept: its file is already durable in the blob store when the step is
// committed; the step's transaction adds its `blobs` row (once per content) and its `run_blobs`
// reference, so a step and the frames it produced are stored together or not at all.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace colorlab::store {

struct StepBlob {
  std::string sha256;
  std::string name;  // unique within the run
  std::string kind;  // raw, average, tiff16, tiff8, jpeg, preview
  std::string media_type;
  std::uint64_t size = 0;
  nlohmann::json meta = nlohmann::json::object();
};

}  // namespace colorlab::store
