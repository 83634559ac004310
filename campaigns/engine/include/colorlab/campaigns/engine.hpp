#pragma once
// The campaign engine: runs a Lua campaign script as a coroutine on the daemon's executor, and
// makes it durable by deterministic replay. Every lab call's result is journaled; the journal,
// the measurements recorded since the last commit and the progress are committed in ONE
// transaction just before the next live lab call (so a committed step is always whole). After a
// crash the script is run again from the start with the stored text, parameters and random seed:
// calls already in the journal are answered from it (no instrument moves), recorded steps already
// stored are skipped, and at the first call past the journal the lab is restored to the state the
// replay says it should be in; from there the script runs live. docs/ARCHITECTURE.md says why.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <boost/asio/awaitable.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/campaigns/call_timing.hpp"
#include "colorlab/campaigns/control.hpp"
#include "colorlab/campaigns/lab.hpp"
#include "colorlab/campaigns/script.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/core/step_records.hpp"

namespace colorlab::campaigns {

// The step's records are the store's too (colorlab/core/step_records.hpp): the engine hands them over as they are.
using JournalEntry = records::JournalEntry;
using RecordedMeasurement = records::Measurement;
// One committed step: the journal, the measurements, the progress, the live calls' timings and the
// blobs the calls kept (typed, named in the run), stored in one transaction.
using StepCommit = records::Step;

// The daemon's side of one execution.
class ExecutionSink {
 public:
  virtual ~ExecutionSink() = default;
  // Durable on return; throws Error{io_error} if the disk refused it (nothing is half-stored).
  virtual void commit(const StepCommit& step) = 0;
  // The same, durable when it completes: the engine commits every step this way (before each live call, and the
  // last when the run ends), and the daemon runs it on a thread of its own, so that its io thread serves meanwhile
  // (issue 27). The step is copied before the first suspension; the engine does nothing else for this execution
  // until it completes.
  virtual boost::asio::awaitable<void> commit_awaiting(const StepCommit& step) {
    commit(step);
    co_return;
  }
  // The lab was brought back after a resume (for the event log).
  virtual void restored(const nlohmann::json& actions) = 0;
  // What the execution is doing now, for logs and systemd's STATUS=.
  virtual void status_text(const std::string& text) = 0;
  // The execution waits out a condition (an instrument gone, a lamp out, a full disk) and then goes
  // on by itself with the interrupted step. May throw (a full disk refuses the status too).
  virtual void suspended(const std::string& /*reason*/, const Error& /*cause*/) {}
  virtual void resumed(const nlohmann::json& /*how*/) {}
};

struct RunOutcome {
  enum class Kind {
    finished,
    paused,
    aborted,
    suspended,
    failed
  };
  Kind kind = Kind::failed;
  nlohmann::json result;           // the run function's return value (finished)
  std::optional<Error> error;      // failed
  nlohmann::json script_location;  // failed in the script: {script, line, step, traceback}
  std::string reason;              // paused, aborted, suspended
  std::int64_t calls = 0;          // lab calls made, replayed included
  std::int64_t replayed = 0;       // of which answered from the journal
};

struct ScriptRunSetup {
  std::shared_ptr<const CampaignScript> script;
  nlohmann::json params;               // validated, defaults filled in
  std::vector<JournalEntry> journal;   // committed calls of a previous attempt, in order
  std::set<std::string> stored_steps;  // recorded steps already stored
  std::uint64_t random_seed = 0;
  std::string initial_label;  // progress label to start from
  double initial_progress = 0;
  // After a crash the port, even the unit, may have changed: instrument id → serial recorded when
  // the run started. A unit that now reports another serial pauses the run for the operator
  // (resuming it from the API accepts the unit: verify_serials = false).
  std::map<std::string, std::string> expected_serials;
  bool verify_serials = true;
  // Where long computations run (lab.analysis.characterize): the daemon's worker pool, so its io
  // thread serves meanwhile. Resumes on the engine's executor with the result or the job's error.
  // Empty: they run inline, on the engine's thread.
  std::function<boost::asio::awaitable<nlohmann::json>(std::string what, std::function<nlohmann::json()> job)> compute;
};

boost::asio::awaitable<RunOutcome> run_campaign_script(ScriptRunSetup setup, Lab& lab, ExecutionSink& sink,
                                                       ExecutionControl& control);

}  // namespace colorlab::campaigns
