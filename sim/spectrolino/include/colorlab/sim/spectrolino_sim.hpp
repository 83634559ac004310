#pragma once
// The simulated Spectrolino / SpectroScan T on its own pty. It listens only at its current speed (a
// client at another speed produces framing garbage, so the device stays silent), switches speed after
// answering 4D 2x / D0 20, and paces every answer by the model's device time plus wire time.
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/sim/link_faults.hpp"
#include "colorlab/sim/pty_device.hpp"
#include "colorlab/sim/spectrolino_model.hpp"

namespace colorlab::sim {

struct SpectrolinoFaults {
  LinkFaults link;
  std::optional<std::uint8_t> exec_error;  // e.g. 0x04 lamp failure, answered to measure/calibrate commands
  bool exec_error_once = false;
  double calibration_lifetime_s = 0;  // white calibration expires after this (0 = never)
  bool expire_calibration = false;    // one-shot: forget the calibration now
  bool power_cycle = false;           // one-shot: back to power-on speed and state
};
// "exec_error" accepts a number or a hex string ("04") or a name: lamp_failure, measuring_disabled,
// no_valid_measurement, too_much_light, hardware_failure, not_ready. Throws Error{bad_parameter}.
void from_json(const nlohmann::json& j, SpectrolinoFaults& f);
void to_json(nlohmann::json& j, const SpectrolinoFaults& f);

class SpectrolinoSim final : public PtyDevice {
 public:
  SpectrolinoSim(boost::asio::any_io_executor executor, const Scene& scene, SpectrolinoConfig config,
                 std::uint64_t seed, double time_scale);

  // Must be called on the executor's thread (the control channel's).
  void set_faults(const SpectrolinoFaults& faults);
  const SpectrolinoFaults& faults() const { return faults_; }
  SpectrolinoModel& model() { return model_; }
  const SpectrolinoModel& model() const { return model_; }

  std::uint64_t lines_answered() const { return answered_; }
  std::uint64_t lines_ignored() const { return ignored_; }  // wrong speed, silent or disconnected

 private:
  void on_bytes(std::string_view bytes) override;
  void handle_line(const std::string& line);
  bool link_down() const;

  const Scene& scene_;
  SpectrolinoModel model_;
  SpectrolinoFaults faults_;
  double silent_until_ = -1;
  std::mt19937_64 fault_rng_;
  std::string line_;
  std::uint64_t answered_ = 0, ignored_ = 0;
};

}  // namespace colorlab::sim
