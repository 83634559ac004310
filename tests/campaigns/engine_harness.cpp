#include "engine_harness.hpp"

#include <future>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/use_future.hpp>

namespace colorlab::testing {

void MemorySink::commit(const campaigns::StepCommit& step) {
  if (crash_after && commits.size() >= *crash_after) throw CrashNow{};
  commits.push_back(step);
  if (on_commit) on_commit(commits.size());
}

std::vector<campaigns::JournalEntry> MemorySink::journal() const {
  std::vector<campaigns::JournalEntry> out;
  for (const auto& c : commits) out.insert(out.end(), c.journal.begin(), c.journal.end());
  return out;
}

std::set<std::string> MemorySink::steps() const {
  std::set<std::string> out;
  for (const auto& m : measurements()) out.insert(m.step);
  return out;
}

std::vector<campaigns::RecordedMeasurement> MemorySink::measurements() const {
  std::vector<campaigns::RecordedMeasurement> out;
  for (const auto& c : commits) out.insert(out.end(), c.measurements.begin(), c.measurements.end());
  return out;
}

std::shared_ptr<campaigns::CampaignScript> script_from(const std::string& name, const std::string& source) {
  return std::make_shared<campaigns::CampaignScript>(campaigns::parse_campaign_script(name, source));
}

EngineRun run_script(campaigns::ScriptRunSetup setup, MemorySink& sink, campaigns::ExecutionControl& control,
                     double time_scale, campaigns::OperatorHands* hands) {
  boost::asio::io_context io;
  campaigns::InstrumentSet none;
  campaigns::LabOptions options;
  options.time_scale = time_scale;
  campaigns::Lab lab(io.get_executor(), none, options);
  lab.set_operator(nullptr, hands);
  auto future = boost::asio::co_spawn(io, campaigns::run_campaign_script(std::move(setup), lab, sink, control),
                                      boost::asio::use_future);
  io.run();
  EngineRun r;
  try {
    r.outcome = future.get();
  } catch (const CrashNow&) {
    r.crashed = true;
  }
  return r;
}

}  // namespace colorlab::testing
