#pragma once
// Simulated Konica Minolta LS-110: answers MES with the luminance of the spot it is aimed at
// (the scene's value plus seeded Gaussian noise) and MDS/CLE with OK, at 4800 baud only, like
// the real meter. Faults can be injected at run time: silence (remote mode lost), an error code,
// garbled or partial lines, dropped replies, extra latency.
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <random>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "colorlab/sim/pty_device.hpp"

namespace colorlab::sim {

struct Ls110Faults {
  bool silent = false;             // remote mode lost: no answer at all
  std::string error_code;          // e.g. "ER10": answer MES with it
  bool error_once = false;         // clear error_code after one use
  double garble_probability = 0;   // corrupt a reply's characters
  double partial_probability = 0;  // send only the first half of a reply
  double drop_probability = 0;     // swallow a reply
  double extra_latency_s = 0;      // added device time per command
  double jitter_s = 0;             // uniform 0..jitter added per command
};
void from_json(const nlohmann::json& j, Ls110Faults& f);
void to_json(nlohmann::json& j, const Ls110Faults& f);

struct Ls110Truth {
  double luminance = 0;    // scene value at the aimed spot, cd/m²
  double noise_sigma = 0;  // standard deviation of one reading
};

class Ls110Sim final : public PtyDevice {
 public:
  using TruthSource = std::function<Ls110Truth()>;

  Ls110Sim(boost::asio::any_io_executor executor, TruthSource truth, std::uint64_t seed, double time_scale);

  void set_faults(const Ls110Faults& faults);
  Ls110Faults faults() const;
  Ls110Truth truth() const { return truth_(); }
  std::uint64_t readings_served() const { return readings_; }

  static constexpr double kMeasureSeconds = 0.4;  // integration + processing; not published, plausible
  static constexpr double kCommandSeconds = 0.05;

 private:
  void on_bytes(std::string_view bytes) override;
  void handle_line(const std::string& line, std::size_t wire_bytes);
  void answer(std::string text, double device_seconds, std::size_t request_bytes);

  TruthSource truth_;
  std::mt19937_64 rng_;
  mutable std::mutex mutex_;
  Ls110Faults faults_;
  std::string line_;
  std::uint64_t readings_ = 0;
};

}  // namespace colorlab::sim
