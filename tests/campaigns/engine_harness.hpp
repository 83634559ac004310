#pragma once
// Runs a campaign script through the real engine on a lab with no instruments (only lab.now,
// lab.wait, record, progress, ...), with an in-memory sink that can "crash" after N commits: the
// way to test replay exhaustively without processes.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "colorlab/campaigns/engine.hpp"

namespace colorlab::testing {

struct CrashNow {};  // thrown by the sink: the process "dies" right after a commit

struct MemorySink final : campaigns::ExecutionSink {
  std::vector<campaigns::StepCommit> commits;
  std::optional<std::size_t> crash_after;  // commits to keep before the "crash"
  std::function<void(std::size_t)> on_commit;
  void commit(const campaigns::StepCommit& step) override;
  void restored(const nlohmann::json&) override { ++restores; }
  void status_text(const std::string&) override {}
  int restores = 0;

  std::vector<campaigns::JournalEntry> journal() const;
  std::set<std::string> steps() const;
  std::vector<campaigns::RecordedMeasurement> measurements() const;
};

std::shared_ptr<campaigns::CampaignScript> script_from(const std::string& name, const std::string& source);

struct EngineRun {
  campaigns::RunOutcome outcome;
  bool crashed = false;
};

// Runs to an outcome (or a CrashNow) on a fresh io_context; `hands` do the operator actions they can.
EngineRun run_script(campaigns::ScriptRunSetup setup, MemorySink& sink, campaigns::ExecutionControl& control,
                     double time_scale = 1000, campaigns::OperatorHands* hands = nullptr);

}  // namespace colorlab::testing
