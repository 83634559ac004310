#include "colorlab/daemon/executions.hpp"

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/use_awaitable.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/protocol/problem.hpp"

namespace colorlab::daemon {

namespace asio = boost::asio;
using protocol::ExecutionStatus;

namespace {

class StoreRecorder final : public campaigns::RunRecorder {
 public:
  StoreRecorder(store::Store& store, std::string run_id, const campaigns::InstrumentSet& instruments)
      : store_(store), run_id_(std::move(run_id)), instruments_(instruments) {}

  void record(const campaigns::Measurement& m) override {
    auto instrument = instruments_.find(m.instrument_id);
    bool simulated = instrument ? instrument->identity().simulated : false;
    std::optional<double> value;
    if (!std::isnan(m.value)) value = m.value;
    store_.add_measurement(run_id_, m.step, m.instrument_id, simulated, m.quantity, value, m.unit, m.data);
  }
  bool has_step(const std::string& step) const override { return store_.has_measurement(run_id_, step); }

 private:
  store::Store& store_;
  std::string run_id_;
  const campaigns::InstrumentSet& instruments_;
};

}  // namespace

Executions::Executions(asio::io_context& io, store::Store& store, const campaigns::CampaignRegistry& campaigns,
                       const campaigns::InstrumentSet& instruments)
    : io_(io), store_(store), campaigns_(campaigns), instruments_(instruments) {}

store::ExecutionRecord Executions::start(const std::string& campaign_name, const nlohmann::json& params,
                                         const std::optional<std::string>& idempotency_key) {
  const campaigns::Campaign* campaign = campaigns_.find(campaign_name);
  if (!campaign) {
    std::string names;
    for (auto* c : campaigns_.all()) names += (names.empty() ? "" : ", ") + c->name();
    throw Error(ErrorClass::not_found, "no campaign named '" + campaign_name + "'", "campaigns: " + names);
  }
  campaign->validate(params);

  store::NewRun run;
  run.campaign = campaign_name;
  run.params = params;
  run.idempotency_key = idempotency_key;
  run.instruments = nlohmann::json::array();
  for (const auto& i : instruments_.all()) {
    run.instruments.push_back(drivers::describe(*i));
    if (i->identity().simulated) run.simulated = true;
  }
  auto created = store_.create_execution(run);
  if (!created.created) return created.execution;  // a retried POST with the same Idempotency-Key
  store::ExecutionRecord record = created.execution;

  ++running_;
  asio::co_spawn(
      io_,
      [this, campaign, params, record]() -> asio::awaitable<void> {
        StoreRecorder recorder(store_, record.run_id, instruments_);
        std::string last_step;
        campaigns::CampaignContext ctx{instruments_, recorder, params,
                                       [&](double fraction, const std::string& step) {
                                         last_step = step;
                                         store_.report_progress(record.id, fraction, step);
                                       }};
        store_.start_execution(record);
        nlohmann::json problem;
        nlohmann::json summary;
        ExecutionStatus status = ExecutionStatus::finished_ok;
        try {
          summary = co_await campaign->run(ctx);
        } catch (const Error& e) {
          status = ExecutionStatus::finished_error;
          problem = protocol::problem_from_error(e).to_json();
          if (!e.info().device_code.empty()) problem["device_code"] = e.info().device_code;
          if (!e.info().transcript.empty()) problem["transcript"] = e.info().transcript;
          log::warning("executions", record.id + " failed: " + e.what());
        } catch (const std::exception& e) {
          status = ExecutionStatus::finished_error;
          problem = protocol::problem_from_error(Error(ErrorClass::internal, e.what())).to_json();
          log::error("executions", record.id + " failed: " + e.what());
        }
        try {
          store_.finish_execution(record, status, status == ExecutionStatus::finished_ok ? "done" : last_step, summary,
                                  problem);
        } catch (const Error& e) {
          // The disk failed at the very end: what was committed stays committed; restart marks it interrupted.
          log::error("executions", record.id + ": cannot record the outcome: " + e.what());
        }
        --running_;
      },
      asio::detached);
  return record;
}

}  // namespace colorlab::daemon
