#pragma once
// The dry run's model of the lab: what each lab call would answer, and what about the call is
// outside the instruments' limits. Answers are plausible, not measured: a neutral grey for spectra,
// luminance proportional to the dimmer, the script's own reference colours for a photographed chart,
// so the script's own control flow and analyses run as they would on the night. Each call's answer
// is its row's in the registry (lab_calls.hpp).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/campaigns/instrument_set.hpp"
#include "colorlab/campaigns/lab_calls.hpp"
#include "colorlab/campaigns/lab_state.hpp"
#include "colorlab/campaigns/run_reader.hpp"

namespace colorlab::campaigns {

struct DryProblem {
  std::string kind;  // "limit", "instrument", "parameter"
  std::string message;
};

class DryLab {
 public:
  DryLab(const InstrumentSet& instruments, RunReader* runs) : instruments_(instruments), runs_(runs) {}

  // The role a call needs ("luminance_meter", "table", …), or empty for calls that need none.
  static std::string role_of(const std::string& call);
  // The instrument that would serve a role: offering it now, or of the right kind but not yet
  // connected (it may offer it once connected). nullptr when none could.
  std::shared_ptr<drivers::Instrument> instrument_for(const std::string& role) const;

  // The call's answer; limits it breaks are appended to `problems` (the call is answered anyway so
  // the rest of the campaign is checked too). Throws Error for what stops a real run outright (a
  // reference run that is not there).
  nlohmann::json answer(const std::string& call, const nlohmann::json& args, double lab_now_s,
                        std::vector<DryProblem>& problems);

 private:
  // The calls' answers, one per call that has one: lab_calls.cpp's rows name them.
  friend const std::vector<LabCall>& lab_calls();
  nlohmann::json call_meter_measure(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_wait_stable(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_lamps_select(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_lamps_set(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_lamps_off(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_lamps_names(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_dimmer_set(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_table_move(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_table_measure_at(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_table_read_patch(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_spectro_mode(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_spectro_measure(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_camera_capture(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_camera_photograph_chart(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_camera_photograph_floor(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_runs_chart_reference(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_operator_request(const nlohmann::json& args, DryContext& context);
  nlohmann::json call_now(const nlohmann::json& args, DryContext& context);
  // The id of the instrument that would serve `role`, or "dry-run".
  std::string id_for(const std::string& role) const;
  // {lamps_on}; a lamp the lamp controller does not know is a problem.
  nlohmann::json lamps_lit(std::vector<std::string> on, DryContext& context) const;

  void check_position(const std::string& call, const nlohmann::json& args, std::vector<DryProblem>& problems) const;
  nlohmann::json grey_spectrum(const std::string& role) const;

  const InstrumentSet& instruments_;
  RunReader* runs_;
  LabState state_;
  double start_unix_s_ = 0;
  nlohmann::json chart_placed_ = nlohmann::json::object();  // the last place_chart request's details
};

}  // namespace colorlab::campaigns
