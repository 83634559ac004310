#include "colorlab/verify/compare/stored_request.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "colorlab/core/error.hpp"

namespace colorlab::verify {

using nlohmann::json;

namespace {

Error bad(const std::string& what) {
  return Error(ErrorClass::bad_parameter, "verification: " + what,
               "send the result of a comparison as colorlab verify --json prints it (docs/API.md, POST /v1/verifications)");
}

const json& field(const json& o, const char* key, const std::string& where) {
  if (!o.is_object() || !o.contains(key)) throw bad(where + " has no '" + key + "'");
  return o[key];
}

double num(const json& o, const char* key, const std::string& where) {
  const json& v = field(o, key, where);
  if (!v.is_number() || !std::isfinite(v.get<double>())) throw bad(where + "." + key + " is not a finite number");
  return v.get<double>();
}

std::string str(const json& o, const char* key, const std::string& where) {
  const json& v = field(o, key, where);
  if (!v.is_string() || v.get<std::string>().empty()) throw bad(where + "." + key + " is not a non-empty string");
  return v.get<std::string>();
}

std::vector<double> numbers(const json& o, const char* key, const std::string& where) {
  const json& v = field(o, key, where);
  if (!v.is_array()) throw bad(where + "." + key + " is not an array");
  std::vector<double> out;
  for (const auto& x : v) {
    if (!x.is_number()) throw bad(where + "." + key + " holds a non-number");
    out.push_back(x.get<double>());
  }
  return out;
}

// JSON has one number type: a whole number may arrive as 8.0 (Python's float, any JavaScript client's number), and
// is that whole number; 8.5, a number beyond int, NaN or infinity (not JSON, but a client may build one), a string or
// a boolean are not.
int whole_at_least_1(const json& n, const std::string& name, const std::string& what) {
  constexpr auto kMax = std::numeric_limits<int>::max();
  if (!n.is_number()) throw bad(name + " is not a whole number (" + what + "), got " + n.dump());
  if (n.is_number_float()) {
    const double d = n.get<double>();
    if (!std::isfinite(d) || d != std::floor(d)) throw bad(name + " is not a whole number (" + what + "), got " + n.dump());
    if (d < 1 || d > kMax) throw bad(name + " must be a whole number from 1 to " + std::to_string(kMax) + ", got " + n.dump());
    return static_cast<int>(d);
  }
  const bool in_range = n.is_number_unsigned() ? n.get<std::uint64_t>() >= 1 && n.get<std::uint64_t>() <= static_cast<std::uint64_t>(kMax)
                                               : n.get<std::int64_t>() >= 1 && n.get<std::int64_t>() <= kMax;
  if (!in_range) throw bad(name + " must be a whole number from 1 to " + std::to_string(kMax) + ", got " + n.dump());
  return static_cast<int>(n.get<std::int64_t>());
}

}  // namespace

Verification verification_from_json(const json& result) {
  Verification v;
  const json& items = field(result, "comparisons", "result");
  if (!items.is_array() || items.empty()) throw bad("result.comparisons is not a non-empty array");
  for (std::size_t i = 0; i < items.size(); ++i) {
    const json& c = items[i];
    const std::string at = "comparisons[" + std::to_string(i) + "]";
    Comparison k;
    k.kind = str(c, "kind", at);
    if (k.kind != "colour_7_3" && k.kind != "colour_7_4" && k.kind != "light_spot" && k.kind != "light_floor")
      throw bad(at + ".kind '" + k.kind + "' is none of colour_7_3, colour_7_4, light_spot, light_floor");
    k.where = str(c, "where", at);
    k.rendered = numbers(c, "rendered", at);
    k.measured = numbers(c, "measured", at);
    k.difference = num(c, "difference", at);
    k.expanded = num(c, "expanded", at);
    k.mahalanobis = num(c, "mahalanobis", at);
    k.threshold = num(c, "threshold", at);
    const std::string verdict = str(c, "verdict", at);
    if (verdict != "agrees" && verdict != "differs") throw bad(at + ".verdict '" + verdict + "' is neither agrees nor differs");
    k.verdict = verdict == "differs" ? Verdict::differs : Verdict::agrees;
    // The engine's rule: differs exactly when the distance exceeds the threshold.
    if ((k.mahalanobis > k.threshold) != (k.verdict == Verdict::differs))
      throw bad(at + ".verdict '" + verdict + "' contradicts its distance " + std::to_string(k.mahalanobis) +
                " against the threshold " + std::to_string(k.threshold));
    const json& tell = field(c, "cannot_tell", at);
    if (!tell.is_boolean()) throw bad(at + ".cannot_tell is not a boolean");
    k.cannot_tell = tell.get<bool>();
    // Absent: a client from before the screen's outliers were reported (none stated, none known).
    if (c.contains("noise_left_out") && !c["noise_left_out"].is_null()) {
      if (!c["noise_left_out"].is_boolean()) throw bad(at + ".noise_left_out is not a boolean");
      k.noise_left_out = c["noise_left_out"].get<bool>();
    }
    const json& budget = field(c, "budget", at);
    if (!budget.is_object()) throw bad(at + ".budget is not an object");
    for (const auto& [source, u] : budget.items()) {
      if (!u.is_number()) throw bad(at + ".budget." + source + " is not a number");
      k.budget.emplace_back(source, u.get<double>());
    }
    v.comparisons.push_back(std::move(k));
  }
  if (result.contains("summary") && result["summary"].contains("scales")) {
    for (const auto& s : result["summary"]["scales"]) {
      ScaleUsed u;
      u.kind = str(s, "kind", "summary.scales[]");
      u.how = str(s, "how", "summary.scales[]");
      u.factor = num(s, "factor", "summary.scales[]");
      v.scales.push_back(u);
    }
  }
  if (result.contains("floor_difference")) {
    const json& f = result["floor_difference"];
    if (!f.is_array()) throw bad("result.floor_difference is not an array of rows");
    for (const auto& row : f) {
      if (!row.is_array()) throw bad("result.floor_difference holds a row that is not an array");
      std::vector<double> r;
      for (const auto& x : row) {
        if (x.is_null()) r.push_back(std::numeric_limits<double>::quiet_NaN());
        else if (x.is_number()) r.push_back(x.get<double>());
        else throw bad("result.floor_difference holds a value that is neither a number nor null");
      }
      v.floor_ratio.push_back(std::move(r));
    }
  }
  return v;
}

StoredVerification stored_from_request(const json& body) {
  if (!body.is_object()) throw bad("the body is not a JSON object");
  const std::string rendering = str(body, "rendering", "body");
  const json& against = field(body, "against", "body");
  if (!against.is_array() || against.empty()) throw bad("body.against is not a non-empty array of run ids");
  std::vector<std::string> runs;
  for (const auto& r : against) {
    if (!r.is_string() || r.get<std::string>().empty()) throw bad("body.against holds something that is not a run id");
    runs.push_back(r.get<std::string>());
  }
  CompareOptions options;
  if (body.contains("scale") && !body["scale"].is_null()) {
    options.scale = num(body, "scale", "body");
    if (!(*options.scale > 0)) throw bad("body.scale must be positive (renderer unit -> cd/m²) or null (fitted)");
  }
  if (body.contains("k")) {
    options.k = num(body, "k", "body");
    if (!(options.k > 0)) throw bad("body.k must be positive (the coverage factor of the bands, 2 for about 95 %)");
  }
  // Absent (a client from before they were sent): the only way a verification was made then, on over 8 regions.
  if (body.contains("rendering_noise") && !body["rendering_noise"].is_null()) {
    if (!body["rendering_noise"].is_boolean())
      throw bad("body.rendering_noise is not a boolean (whether the rendering's own noise was in the budget)");
    options.rendering_noise = body["rendering_noise"].get<bool>();
  }
  if (body.contains("noise_neighbours") && !body["noise_neighbours"].is_null())
    options.noise_neighbours = whole_at_least_1(body["noise_neighbours"], "body.noise_neighbours",
                                                "the regions the rendering's noise was pooled over");
  check_options(options);
  json placement;
  if (body.contains("placement") && !body["placement"].is_null()) {
    placement = body["placement"];
    if (!placement.is_object()) throw bad("body.placement is not an object");
    if (placement.dump().size() > 4096) throw bad("body.placement is larger than 4 KiB");
  }
  const Verification v = verification_from_json(field(body, "result", "body"));
  // A verification said to be made without the rendering's noise cannot carry it in a budget.
  if (!options.rendering_noise)
    for (std::size_t i = 0; i < v.comparisons.size(); ++i)
      for (const auto& [source, u] : v.comparisons[i].budget)
        if (source == "rendering noise")
          throw bad("comparisons[" + std::to_string(i) + "].budget has \"rendering noise\" while body.rendering_noise is false");
  if (!options.rendering_noise)
    for (std::size_t i = 0; i < v.comparisons.size(); ++i)
      if (v.comparisons[i].noise_left_out)
        throw bad("comparisons[" + std::to_string(i) + "].noise_left_out is true while body.rendering_noise is false");
  auto stored = to_store(v, rendering, runs, options, placement);
  // The pooling is the client's engine's, not this daemon's: stored as the body states it, null when it does not (a
  // client from before the field, whose pooling the body cannot tell).
  json pooling = body.contains("noise_pooling") ? body["noise_pooling"] : json(nullptr);
  if (!pooling.is_null()) {
    if (!options.rendering_noise) throw bad("body.noise_pooling is " + pooling.dump() + " while body.rendering_noise is false");
    if (pooling != kNoisePooling)
      throw bad("body.noise_pooling must be \"" + std::string(kNoisePooling) + "\" (or null, not recorded), got " + pooling.dump());
  }
  stored.params["noise_pooling"] = pooling;
  return stored;
}

json store_request(const Verification& v, const std::string& rendering, const std::vector<std::string>& against,
                   const CompareOptions& options, const json& placement) {
  json body = verification_params(rendering, against, options, placement);
  body["result"] = v.to_json();
  return body;
}

}  // namespace colorlab::verify
