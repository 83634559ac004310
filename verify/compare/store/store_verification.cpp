#include "store_verification.hpp"

#include "colorlab/core/error.hpp"
#include "colorlab/protocol/problem.hpp"

namespace colorlab::verify {

std::string store_verification(store::Store& store, const StoredVerification& v) {
  store::NewRun run;
  run.campaign = kVerifyCampaign;
  run.params = v.params;
  run.instruments = nlohmann::json::object();
  auto created = store.create_execution(run);
  auto& execution = created.execution;
  try {
    store.start_execution(execution);
    store::StepRecord step;
    step.measurements = v.measurements;
    step.progress = 1.0;
    step.step = "compared";
    store.commit_step(execution, step);
    store.finish_execution(execution, protocol::ExecutionStatus::finished_ok, "compared", v.summary, nullptr);
  } catch (const Error& e) {
    // An unfinished row would hold the lab (one execution at a time) until the next start-up: ended with the
    // cause if the store still takes a write; if it does not, the start-up's resume ends it.
    try {
      store.finish_execution(execution, protocol::ExecutionStatus::finished_error, "compared", nullptr,
                             protocol::problem_from_error(e).to_json(), e.what());
    } catch (const Error&) {
    }
    throw;
  }
  return execution.run_id;
}

}  // namespace colorlab::verify
