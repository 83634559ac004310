#include "store_verification.hpp"

namespace colorlab::verify {

std::string store_verification(store::Store& store, const StoredVerification& v) {
  store::NewRun run;
  run.campaign = kVerifyCampaign;
  run.params = v.params;
  run.instruments = nlohmann::json::object();
  auto created = store.create_execution(run);
  auto& execution = created.execution;
  store.start_execution(execution);
  store::StepRecord step;
  step.measurements = v.measurements;
  step.progress = 1.0;
  step.step = "compared";
  store.commit_step(execution, step);
  store.finish_execution(execution, protocol::ExecutionStatus::finished_ok, "compared", v.summary, nullptr);
  return execution.run_id;
}

}  // namespace colorlab::verify
