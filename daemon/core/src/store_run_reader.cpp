#include "colorlab/daemon/store_run_reader.hpp"

namespace colorlab::daemon {

std::optional<campaigns::StoredRun> StoreRunReader::run(const std::string& run_id) {
  auto r = store_.run(run_id);
  if (!r) return std::nullopt;
  campaigns::StoredRun out;
  out.id = r->id;
  out.campaign = r->campaign;
  out.status = r->status;
  out.simulated = r->simulated;
  out.params = r->params;
  for (auto& m : store_.measurements(run_id)) {
    out.measurements.push_back({std::move(m.step), std::move(m.instrument_id), std::move(m.quantity), m.value,
                                std::move(m.unit), std::move(m.data)});
  }
  return out;
}

}  // namespace colorlab::daemon
