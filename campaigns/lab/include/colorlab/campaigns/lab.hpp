#pragma once
// The live side of the lab API: carries out a script's calls on the daemon's instruments, by role
// (the first instrument offering the capability), waiting for an instrument that is still
// connecting. Also brings the lab back to a journal's desired state after a resume, and to a safe
// state at shutdown. Times a script gives are lab seconds; with the simulated lab they shrink by
// its time scale.
#include <chrono>
#include <map>
#include <optional>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/awaitable.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/campaigns/control.hpp"
#include "colorlab/campaigns/frame_keeper.hpp"
#include "colorlab/campaigns/instrument_set.hpp"
#include "colorlab/campaigns/lab_calls.hpp"
#include "colorlab/campaigns/lab_state.hpp"
#include "colorlab/campaigns/light_reference.hpp"
#include "colorlab/campaigns/operator_desk.hpp"
#include "colorlab/campaigns/run_reader.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::drivers::camera {
class CameraInstrument;
}

namespace colorlab::campaigns {

struct StabilityCriterion {
  double tolerance_pct = 0.5;  // drift over the window, from a straight-line fit, in % of the mean
  double window_s = 60;        // lab seconds
  double interval_s = 5;       // lab seconds between readings
  double timeout_s = 1800;     // lab seconds
  static StabilityCriterion from_json(const nlohmann::json& j, const StabilityCriterion& defaults);
};

// How an execution waits out a condition that stops it (an instrument gone, a lamp out, a full
// disk): it is suspended, the condition is checked every `retry_s`, and once it has cleared and
// stayed clear for `settle_s` the interrupted step is measured again. After `max_s` it fails.
struct SuspendPolicy {
  double retry_s = 30;   // lab seconds between checks (at least 0.2 s of wall time)
  double settle_s = 60;  // lab seconds the condition must stay clear
  double max_s = 8 * 3600;
  // A reading below this fraction of what the last stable reading predicts means a lamp went out, at the aim
  // where the lamps were found stable.
  double dropout_fraction = 0.2;
  // The same at another aim. The floor of one cabinet differs between spots by far more than a reading's noise
  // (the simulated CWF's back corner reads an eighth of its middle; the dissertation's CWF windows differ by
  // 40 cd/m² of stdev), so only a cabinet gone nearly dark can be told from a dimmer spot there.
  double dropout_fraction_other_aim = 0.05;
  // A reading that differs by more than this from the reading at the same aim, lamps and dimmer level since
  // the lamps were found stable means a lamp drifted. Above what the same light can read: the LS-110's
  // repeatability (4 σ of two readings ≈ 0.6 %) plus what a lamp accepted as stable may still rise (≤ 1 %
  // with a 0.5 %/60 s criterion and a 2-minute warm-up); below what a §6.2 map must not mix silently.
  double drift_tolerance_pct = 3;
};

struct LabOptions {
  double time_scale = 1;               // lab seconds per wall-clock second (the simulator's time scale)
  StabilityCriterion warmup;           // how a resume decides that relit lamps are stable again
  double lamp_warmup_s = 900;          // with no luminance meter: wait this long after relighting
  bool lamps_off_at_shutdown = false;  // otherwise lamps stay as they are (a warm cabinet for the next run)
  std::chrono::seconds connect_timeout{60};
  SuspendPolicy suspend;
};

class Lab {
 public:
  Lab(boost::asio::any_io_executor executor, const InstrumentSet& instruments, LabOptions options);

  // Throws Error{not_found} naming the first role no configured instrument offers.
  void check_needs(const std::vector<std::string>& roles) const;
  // One lab call, live, through its row in the registry (lab_calls.hpp). Long waits end early with
  // Error{aborted} when `control` asks.
  boost::asio::awaitable<nlohmann::json> perform(const std::string& call, const nlohmann::json& args,
                                                 const ExecutionControl& control);
  // Why a failed call should suspend the execution rather than fail it ("lamp", "instrument"), or
  // nullopt for a failure no waiting mends (a bad argument, a script error, a device error code).
  static std::optional<std::string> suspend_cause(const Error& e);
  // Returns once the condition behind `cause` has cleared and stayed clear for the settle time;
  // Error{aborted} when `control` asks, or `cause` again after SuspendPolicy::max_s. `args` are the failed
  // call's: an instrument is brought back as that call chose it (a camera named by id or kind).
  boost::asio::awaitable<nlohmann::json> await_recovery(const std::string& call, const nlohmann::json& args,
                                                        const Error& cause, const ExecutionControl& control);
  // One retry interval of a suspension (for conditions the engine checks itself, a full disk).
  boost::asio::awaitable<void> wait_retry(const ExecutionControl& control);
  // Brings the instruments to `desired`; returns what it did, for the event log.
  boost::asio::awaitable<nlohmann::json> restore(const LabState& desired, const ExecutionControl& control);
  // Table home with the head up; lamps off if configured. Errors are logged, not thrown.
  boost::asio::awaitable<void> safe_state();
  // A run has ended (in any state): what the lab's hands did for it and left out of the lab's rest is put back
  // (OperatorHands::put_back, `state`'s done_by_hands). Returns what was done; errors are logged, not thrown.
  boost::asio::awaitable<nlohmann::json> put_back(const LabState& state);
  // Connects the instruments named in `expected` (id → serial the run started with) and lists those
  // that now report another serial: "id: the run started with serial A, now B".
  boost::asio::awaitable<std::vector<std::string>> serial_mismatches(std::map<std::string, std::string> expected);

  // Where operator requests go, and who can do them without a person (the simulated lab).
  void set_operator(OperatorDesk* desk, OperatorHands* hands) {
    desk_ = desk;
    hands_ = hands;
  }

  // Where lab.runs.* reads earlier runs (the daemon's store); without one those calls fail.
  void set_run_reader(RunReader* runs) { runs_ = runs; }
  // Where frames worth keeping go (the daemon's blob store); without one nothing is kept.
  void set_frame_keeper(FrameKeeper* keeper);
  FrameKeeper* frame_keeper() const { return keeper_; }
  // The blobs the last perform() of this execution kept, in the order kept (typed, for the step that journals the
  // call); forgets them.
  std::vector<KeptBlob> take_kept(const std::string& execution_id);
  // The execution has ended (however it ended): its ledger goes, so a week of nights leaves none behind.
  void forget_kept(const std::string& execution_id) { ledgers_.erase(execution_id); }
  // Executions holding a ledger now: none once every execution has ended.
  std::size_t executions_keeping() const { return ledgers_.size(); }
  // What a dry run of a campaign on this lab needs to know of it.
  const OperatorHands* hands() const { return hands_; }
  RunReader* run_reader() const { return runs_; }
  const InstrumentSet& instruments() const { return instruments_; }

  const LabOptions& options() const { return options_; }
  double time_scale() const { return options_.time_scale; }

 private:
  // The calls' handlers, one per call: lab_calls.cpp's rows name them.
  friend const std::vector<LabCall>& lab_calls();
  boost::asio::awaitable<nlohmann::json> call_meter_measure(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_wait_stable(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_lamps_select(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_lamps_set(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_lamps_off(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_lamps_names(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_dimmer_set(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_table_move(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_table_home(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_table_head_up(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_table_head_down(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_table_hold_paper(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_table_measure_at(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_table_read_patch(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_spectro_mode(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_spectro_calibrate(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_spectro_measure(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_camera_configure(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_camera_capture(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_camera_photograph_chart(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_camera_photograph_floor(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_runs_chart_reference(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_operator_request(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_wait(const nlohmann::json& args, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> call_now(const nlohmann::json& args, const ExecutionControl& control);
  // The keeper a call of `control`'s execution keeps its frames through (notes them for take_kept()), or nullptr.
  FrameKeeper* call_keeper(const ExecutionControl& control);
  // The camera an options table names ({camera = id or kind}), else the one serving the role; connected.
  boost::asio::awaitable<std::shared_ptr<drivers::camera::CameraInstrument>> camera_named_in(const nlohmann::json& options);

  // The last stable reading and the light it was taken under: the yardstick for a lamp dropout.
  struct StableLight {
    double luminance = 0;
    std::vector<std::string> lamps;
    double dimmer_percent = 100;
  };

  template <class T>
  std::shared_ptr<T> role(const std::string& name) const;  // or Error{not_found}
  template <class T>
  std::shared_ptr<T> find_role(const std::string& name) const;  // or nullptr
  // The role's instrument, connected (connecting candidates first if none offers it yet).
  template <class T>
  boost::asio::awaitable<std::shared_ptr<T>> acquire(const std::string& name);
  template <class T>
  bool may_offer(const std::string& name) const;
  boost::asio::awaitable<void> ready(drivers::Instrument& instrument);
  boost::asio::awaitable<void> sleep_lab_seconds(double seconds, const ExecutionControl& control);
  boost::asio::awaitable<nlohmann::json> wait_stable(const StabilityCriterion& c, const ExecutionControl& control);
  boost::asio::awaitable<void> switch_lamps(std::vector<std::string> on);
  boost::asio::awaitable<nlohmann::json> operator_request(const nlohmann::json& spec, const ExecutionControl& control);
  boost::asio::awaitable<void> sleep_wall(std::chrono::steady_clock::duration d, const ExecutionControl& control);
  // Throws Error{needs_operator, "lamp:dropout"} when `luminance` is far below what the last stable
  // reading under the same lamps predicts at the current dimmer level.
  void check_dropout(double luminance, const std::string& unit) const;
  // Throws Error{needs_operator, "lamp:drift"} when `luminance` differs from the reading at this aim, lamps
  // and dimmer level since the lamps were found stable by more than SuspendPolicy::drift_tolerance_pct.
  void check_drift(double luminance, const std::string& unit);
  // The lamps lit now were found stable with this reading: the yardstick for a dropout and for a drift.
  void note_stable(double luminance);
  StableLight light_now(double luminance) const;
  // A call of another execution than the last: forgets what the light reference and a suspension held.
  void follow_execution(const ExecutionControl& control);
  std::vector<std::string> lit_lamps() const;

  boost::asio::any_io_executor executor_;
  const InstrumentSet& instruments_;
  LabOptions options_;
  // Lamps this process has seen lit and stable since it last switched them: a resume in the same
  // process need not wait for them again; a fresh process knows nothing and waits.
  std::set<std::string> known_warm_;
  std::optional<StableLight> stable_light_;
  // Whether the meter may have been aimed elsewhere since stable_light_ was read (check_dropout's bound).
  bool aimed_since_stable_ = false;
  // The yardstick for a drift: per dimmer level at the meter's present aim.
  LightReference light_;
  // What the last suspension for the light found (the level it settled at and how far it moved): added to
  // the result of the call made again, so a script knows its readings before it may be off.
  std::optional<nlohmann::json> resumed_note_;
  std::string light_execution_;  // whose readings light_ holds
  double dimmer_percent_ = 100;
  OperatorDesk* desk_ = nullptr;
  OperatorHands* hands_ = nullptr;
  RunReader* runs_ = nullptr;
  FrameKeeper* keeper_ = nullptr;
  // In front of keeper_ for the calls: notes what each call kept, one ledger per execution. Two executions may run
  // at once on this lab (a direct start beside the night queue) and a call suspends (camera, lamps): with one ledger
  // the call of one would clear, or its step take, the frames of the other's call. Touched on the lab's executor
  // only; a node stays put while a worker thread keeps through it.
  std::map<std::string, KeepLedger> ledgers_;
};

}  // namespace colorlab::campaigns
