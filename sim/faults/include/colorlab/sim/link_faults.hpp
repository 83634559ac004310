#pragma once
// Link-level faults shared by the simulated serial instruments: extra latency and jitter, dropped,
// garbled or partial replies, and silence (remote mode lost, cable pulled) for a while or for good.
// Settable from the lab's TOML and at run time ({"cmd":"fault",...}); see docs/simulator.md.
#include <optional>
#include <random>
#include <string>

#include <nlohmann/json_fwd.hpp>

namespace colorlab::sim {

struct LinkFaults {
  double extra_latency_s = 0;      // added device time per reply
  double jitter_s = 0;             // uniform 0..jitter added per reply
  double drop_probability = 0;     // swallow a reply
  double garble_probability = 0;   // corrupt characters inside a reply (the frame ends stay)
  double partial_probability = 0;  // send only the first half of a reply
  bool silent = false;             // no answers at all until cleared
  double disconnect_s = 0;         // one-shot: no answers for this many simulated seconds from when it is set
};
// Unknown keys are ignored here so each instrument can add its own; values are range-checked
// (probabilities 0..1, times >= 0) with Error{bad_parameter}.
void from_json(const nlohmann::json& j, LinkFaults& f);
void to_json(nlohmann::json& j, const LinkFaults& f);

// Applies the faults to one reply. Returns nullopt when the reply is dropped; adds latency and jitter
// to `extra_seconds`. `frame_chars` is how many characters at each end must stay intact (e.g. 1 for
// ':' and 2 for CR LF are passed as lead 1, tail 2).
std::optional<std::string> apply_link_faults(const LinkFaults& f, std::string reply, std::mt19937_64& rng,
                                             double& extra_seconds, std::size_t lead, std::size_t tail);

}  // namespace colorlab::sim
