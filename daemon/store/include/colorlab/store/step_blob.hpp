#pragma once
// A blob a campaign step kept: its file is already durable in the blob store when the step is
// committed; the step's transaction adds its `blobs` row (once per content) and its `run_blobs`
// reference, so a step and the frames it produced are stored together or not at all.
#include "colorlab/core/step_records.hpp"

namespace colorlab::store {

// `name` is the run's: "<call>#<seq>/<name>" as the engine named it.
using StepBlob = records::BlobRef;

}  // namespace colorlab::store
