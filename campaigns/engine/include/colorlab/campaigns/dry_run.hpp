#pragma once
// The dry run: a campaign run through the same script, the same lab API and the same argument
// checks as a real execution, against a lab that moves nothing. Every lab call is answered by a
// model of the lab (plausible readings, the chart's reference colours where the script passes them)
// and costs what this lab's calls have cost before (TimingBook), so the run says, before the night
// starts: whether every parameter and position is within the instruments' limits (the table's
// travel, the dimmer's range, lamp names), whether every instrument it needs is there, whether the
// disk has room, which operator actions it will ask for, and how long it will take and where the
// time goes. Nothing is stored and no instrument is touched; lab.runs.* reads the store as a real
// run would.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include <boost/asio/awaitable.hpp>

#include <nlohmann/json.hpp>

#include "colorlab/campaigns/call_timing.hpp"
#include "colorlab/campaigns/instrument_set.hpp"
#include "colorlab/campaigns/lab.hpp"
#include "colorlab/campaigns/operator_desk.hpp"
#include "colorlab/campaigns/run_reader.hpp"
#include "colorlab/campaigns/script.hpp"

namespace colorlab::campaigns {

struct DryRunSetup {
  std::shared_ptr<const CampaignScript> script;
  nlohmann::json params;  // validated, defaults filled in
  const InstrumentSet* instruments = nullptr;
  LabOptions options;  // time scale, the stability criterion, the configured lamp warm-up
  TimingBook timings;  // what each kind of call has cost on this lab
  RunReader* runs = nullptr;
  const OperatorHands* hands = nullptr;  // actions the simulated lab does itself
  std::filesystem::path state_dir;       // where the run's data would go (free space)
  std::size_t max_calls = 2'000'000;     // a script waiting for a reading the model never gives
  // Where the script's long computations run (as ScriptRunSetup::compute): in the daemon, its worker
  // pool, so a dry run's fits leave the io thread free. Empty: inline.
  std::function<boost::asio::awaitable<nlohmann::json>(std::string what, std::function<nlohmann::json()> job)> compute;
};

// {campaign, ok, problems = [{kind, message, line?, call?}], stopped_at?, calls, measurements,
//  instruments = [{role, instrument, state, simulated}], operator_actions = [{action, prompt, count,
//  options, default, timeout_s, by}], lamp_warmups,
//  (measured_share: of the estimate, the part not from assumed figures or operator timeouts) estimate = {lab_seconds, wall_seconds, time_scale,
//  measured_share, operator_wait_s, script_wall_s, by_key = [{key, calls, lab_seconds, source, n}]},
//  storage = {estimated_bytes, available_bytes}}.
// Throws only for a script that cannot be loaded at all; everything else is a problem in the report.
nlohmann::json dry_run_campaign(const DryRunSetup& setup);
// The same as a coroutine on the caller's executor (the daemon's io thread), which it leaves between
// stretches of the script's computation and while setup.compute runs the analyses.
boost::asio::awaitable<nlohmann::json> dry_run_campaign_async(DryRunSetup setup);

// The nominal cost of a call never timed on this lab, in lab seconds per unit (assumed figures:
// no source publishes these instruments' timings), and why.
double nominal_lab_seconds(const std::string& key, const LabOptions& options);

}  // namespace colorlab::campaigns
