#pragma once
// The store seen as campaigns::RunReader: what lab.runs.* may read of earlier runs, read-only.
#include "colorlab/campaigns/run_reader.hpp"
#include "colorlab/store/store.hpp"

namespace colorlab::daemon {

class StoreRunReader final : public campaigns::RunReader {
 public:
  explicit StoreRunReader(store::Store& store) : store_(store) {}
  std::optional<campaigns::StoredRun> run(const std::string& run_id) override;

 private:
  store::Store& store_;
};

}  // namespace colorlab::daemon
