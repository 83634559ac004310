#include "colorlab/sim/ls110_sim.hpp"

#include <nlohmann/json.hpp>

#include "colorlab/wire/ls110_protocol.hpp"

namespace colorlab::sim {

void from_json(const nlohmann::json& j, Ls110Faults& f) {
  f.silent = j.value("silent", f.silent);
  f.error_code = j.value("error_code", f.error_code);
  f.error_once = j.value("error_once", f.error_once);
  f.garble_probability = j.value("garble_probability", f.garble_probability);
  f.partial_probability = j.value("partial_probability", f.partial_probability);
  f.drop_probability = j.value("drop_probability", f.drop_probability);
  f.extra_latency_s = j.value("extra_latency_s", f.extra_latency_s);
  f.jitter_s = j.value("jitter_s", f.jitter_s);
}

void to_json(nlohmann::json& j, const Ls110Faults& f) {
  j = {{"silent", f.silent},
       {"error_code", f.error_code},
       {"error_once", f.error_once},
       {"garble_probability", f.garble_probability},
       {"partial_probability", f.partial_probability},
       {"drop_probability", f.drop_probability},
       {"extra_latency_s", f.extra_latency_s},
       {"jitter_s", f.jitter_s}};
}

Ls110Sim::Ls110Sim(boost::asio::any_io_executor executor, TruthSource truth, std::uint64_t seed, double time_scale)
    : PtyDevice(executor, "ls110", time_scale), truth_(std::move(truth)), rng_(seed) {}

void Ls110Sim::set_faults(const Ls110Faults& faults) {
  std::lock_guard lock(mutex_);
  faults_ = faults;
}

Ls110Faults Ls110Sim::faults() const {
  std::lock_guard lock(mutex_);
  return faults_;
}

void Ls110Sim::on_bytes(std::string_view bytes) {
  for (char c : bytes) {
    if (c == '\n' || c == '\r') {
      if (!line_.empty()) {
        std::size_t wire = line_.size() + 2;
        std::string line = std::move(line_);
        line_.clear();
        handle_line(line, wire);
      }
    } else if (line_.size() < 256) {
      line_ += c;
    }
  }
}

void Ls110Sim::answer(std::string text, double device_seconds, std::size_t request_bytes) {
  Ls110Faults f = faults();
  std::uniform_real_distribution<double> u(0.0, 1.0);
  if (f.drop_probability > 0 && u(rng_) < f.drop_probability) return;
  if (f.partial_probability > 0 && u(rng_) < f.partial_probability) text.resize(text.size() / 2);
  if (f.garble_probability > 0 && u(rng_) < f.garble_probability && text.size() > 3) {
    // Line noise flips characters but the meter still ends the line.
    for (std::size_t i = 0; i + 2 < text.size(); i += 2) text[i] = static_cast<char>('#' + (rng_() % 20));
  }
  double extra = f.extra_latency_s + (f.jitter_s > 0 ? u(rng_) * f.jitter_s : 0);
  reply(std::move(text), device_seconds + extra, request_bytes);
}

void Ls110Sim::handle_line(const std::string& line, std::size_t wire_bytes) {
  // A client at the wrong speed would only produce framing garbage at the meter: it stays silent.
  if (client_settings().baud != 4800) return;
  Ls110Faults f = faults();
  if (f.silent) return;

  if (line == "MES") {
    if (!f.error_code.empty()) {
      if (f.error_once) {
        std::lock_guard lock(mutex_);
        faults_.error_code.clear();
      }
      answer(wire::ls110::format_error(f.error_code), kMeasureSeconds, wire_bytes);
      return;
    }
    Ls110Truth t = truth_();
    // σ times a standard normal, not normal_distribution(0, σ): that one requires σ > 0 and a noiseless meter
    // (σ = 0, the default) broke it (_GLIBCXX_ASSERTIONS, the asan preset). Same draws and values as before.
    std::normal_distribution<double> n01(0.0, 1.0);
    double value = std::max(0.0, t.luminance + t.noise_sigma * n01(rng_));
    ++readings_;
    answer(wire::ls110::format_ok(value, 0), kMeasureSeconds, wire_bytes);
  } else if (line.rfind("MDS", 0) == 0) {
    std::string mode = line.substr(3);
    if (!mode.empty() && mode[0] == ',') mode.erase(0, 1);
    bool valid = mode == "04" || mode == "08" || mode == "09";
    answer(valid ? "OK00\r\n" : wire::ls110::format_error("ER01"), kCommandSeconds, wire_bytes);
  } else if (line == "CLE") {
    answer("OK00\r\n", kCommandSeconds, wire_bytes);
  } else {
    answer(wire::ls110::format_error("ER00"), kCommandSeconds, wire_bytes);
  }
}

}  // namespace colorlab::sim
