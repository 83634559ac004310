#include "colorlab/sim/link_faults.hpp"

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"

namespace colorlab::sim {

namespace {

double checked(const nlohmann::json& j, const char* key, double current, double max) {
  if (!j.contains(key)) return current;
  if (!j[key].is_number()) throw Error(ErrorClass::bad_parameter, std::string("fault '") + key + "' must be a number");
  double v = j[key].get<double>();
  if (v < 0 || v > max) {
    throw Error(ErrorClass::bad_parameter,
                std::string("fault '") + key + "' = " + std::to_string(v) + " is outside 0.." + std::to_string(max));
  }
  return v;
}

}  // namespace

void from_json(const nlohmann::json& j, LinkFaults& f) {
  if (!j.is_object()) throw Error(ErrorClass::bad_parameter, "faults must be an object");
  constexpr double big = 1e9;
  f.extra_latency_s = checked(j, "extra_latency_s", f.extra_latency_s, big);
  f.jitter_s = checked(j, "jitter_s", f.jitter_s, big);
  f.drop_probability = checked(j, "drop_probability", f.drop_probability, 1);
  f.garble_probability = checked(j, "garble_probability", f.garble_probability, 1);
  f.partial_probability = checked(j, "partial_probability", f.partial_probability, 1);
  f.disconnect_s = checked(j, "disconnect_s", f.disconnect_s, big);
  if (j.contains("silent")) {
    if (!j["silent"].is_boolean()) throw Error(ErrorClass::bad_parameter, "fault 'silent' must be true or false");
    f.silent = j["silent"].get<bool>();
  }
}

void to_json(nlohmann::json& j, const LinkFaults& f) {
  j = {
      {"extra_latency_s", f.extra_latency_s},
      {"jitter_s", f.jitter_s},
      {"drop_probability", f.drop_probability},
      {"garble_probability", f.garble_probability},
      {"partial_probability", f.partial_probability},
      {"silent", f.silent},
      {"disconnect_s", f.disconnect_s},
  };
}

std::optional<std::string> apply_link_faults(const LinkFaults& f, std::string reply, std::mt19937_64& rng,
                                             double& extra_seconds, std::size_t lead, std::size_t tail) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // Draw every variate each time so that one fault's setting does not shift another's random stream.
  double drop = u(rng), partial = u(rng), garble = u(rng), jitter = u(rng);
  extra_seconds += f.extra_latency_s + jitter * f.jitter_s;
  if (drop < f.drop_probability) return std::nullopt;
  if (garble < f.garble_probability && reply.size() > lead + tail) {
    static constexpr char noise[] = "GHKXZ#?*";
    for (std::size_t i = lead; i + tail < reply.size(); i += 3) reply[i] = noise[rng() % (sizeof noise - 1)];
  }
  if (partial < f.partial_probability) reply.resize(reply.size() / 2);
  return reply;
}

}  // namespace colorlab::sim
