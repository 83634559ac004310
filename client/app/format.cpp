#include "format.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace colorlab::cli {

using nlohmann::json;

namespace {

std::string str(const json& j, const char* key) {
  if (!j.contains(key) || j[key].is_null()) return "-";
  if (j[key].is_string()) return j[key].get<std::string>();
  return j[key].dump();
}

std::string number(double v, int decimals = 2) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// 5430 s → "1 h 30 min 30 s"; short durations keep a decimal.
std::string duration(double s) {
  if (s < 60) return number(s, s < 10 ? 1 : 0) + " s";
  const long t = std::lround(s);
  std::string out;
  if (t >= 3600) out += std::to_string(t / 3600) + " h ";
  if (t >= 60) out += std::to_string((t % 3600) / 60) + " min ";
  return out + std::to_string(t % 60) + " s";
}

}  // namespace

// GET /v1/shipping (docs/fleet.md, "Lag"): what waits to ship and what the agent last said.
std::string format_shipping(const json& s) {
  std::ostringstream o;
  if (!s.value("enabled", false) && s["agent"].is_null()) return "  shipping: off (no [ship] section)\n";
  const json& lag = s["lag"];
  const auto waiting = lag.value("unshipped_runs", 0LL);
  if (waiting == 0) {
    o << "  shipping: every ended run has shipped (position " << str(s, "shipped_position") << ")\n";
  } else {
    o << "  shipping: " << waiting << " ended run(s) not shipped; the oldest " << str(lag, "oldest_unshipped_run") << " ("
      << str(lag, "oldest_unshipped_status") << ") ended " << str(lag, "oldest_unshipped_ended_at");
    if (lag["age_s"].is_number()) o << ", " << duration(lag["age_s"].get<double>()) << " ago";
    o << "\n";
  }
  const json& agent = s["agent"];
  if (!agent.is_object()) {
    o << "  agent: no cycle recorded yet (is colorlab-ship running?)\n";
  } else {
    o << "  agent: last cycle " << (agent.value("ok", false) ? "ok" : "FAILED");
    if (s["agent_seen_s_ago"].is_number()) o << ", " << duration(s["agent_seen_s_ago"].get<double>()) << " ago";
    o << "\n";
  }
  const json& e = s["last_error"];
  if (e.is_object()) {
    o << "  last error (" << str(e, "at") << "): " << str(e, "message") << "\n";
    if (e.contains("hint") && e["hint"].is_string() && !e["hint"].get<std::string>().empty()) {
      o << "    hint: " << e["hint"].get<std::string>() << "\n";
    }
  }
  return o.str();
}

std::string format_status(const json& root) {
  std::ostringstream o;
  o << "colorlabd " << str(root, "server_version") << " (API v" << str(root, "api_version") << ")";
  if (root.value("simulated_lab", false)) o << " — SIMULATED LAB";
  o << "\n  up since " << str(root, "started_at") << ", running executions: " << str(root, "running_executions") << "\n";
  if (root.contains("shipping") && root["shipping"].is_object()) o << format_shipping(root["shipping"]);
  return o.str();
}

std::string format_instruments(const json& list) {
  std::ostringstream o;
  if (list["items"].empty()) return "no instruments configured\n";
  for (const auto& i : list["items"]) {
    const std::string model = i.value("model", std::string());
    o << str(i, "id") << "  " << (model.empty() ? str(i, "kind") : model) << "  [" << str(i, "state") << "]"
      << (i.value("simulated", false) ? "  (simulated)" : "") << "\n    port " << str(i, "port");
    // An absent instrument's reason says it all; its problem (the same failure) would repeat it.
    if (i.contains("reason")) o << "\n    absent: " << i["reason"].get<std::string>();
    else if (i.contains("problem")) o << "\n    problem: " << i["problem"].get<std::string>();
    o << "\n";
  }
  return o.str();
}

std::string format_campaigns(const json& list) {
  std::ostringstream o;
  for (const auto& c : list["items"]) {
    if (c.value("kind", std::string()) == "sequence") {
      o << format_sequence(c);
      continue;
    }
    o << str(c, "name") << "  (" << str(c, "origin") << ")\n    " << str(c, "description") << "\n";
    if (c.contains("needs") && !c["needs"].empty()) {
      o << "    needs:";
      for (const auto& n : c["needs"]) o << " " << n.get<std::string>();
      o << "\n";
    }
    for (const auto& [k, v] : c["parameters"].items()) {
      o << "    --param " << k << "=" << (v.contains("default") && !v["default"].is_null() ? v["default"].dump() : "")
        << "   " << v.value("type", std::string());
      if (!v.value("unit", std::string()).empty()) o << ", " << v["unit"].get<std::string>();
      if (v.contains("min")) o << ", ≥ " << v["min"].dump();
      if (v.contains("max")) o << ", ≤ " << v["max"].dump();
      if (v.contains("values")) o << ", one of " << v["values"].dump();
      if (!v.value("description", std::string()).empty()) o << " — " << v["description"].get<std::string>();
      o << "\n";
    }
  }
  if (list.contains("broken")) {
    for (const auto& b : list["broken"]) o << "BROKEN " << str(b, "path") << "\n    " << str(b, "error") << "\n";
  }
  return o.str();
}

std::string format_runs(const json& page) {
  std::ostringstream o;
  if (page["items"].empty()) return "no runs yet\n";
  for (const auto& r : page["items"]) {
    o << str(r, "id") << "  " << str(r, "campaign") << "  " << str(r, "status") << "  " << str(r, "created_at")
      << (r.value("simulated", false) ? "  (simulated)" : "") << "\n";
  }
  if (page.contains("next_cursor") && !page["next_cursor"].is_null()) {
    o << "more: colorlab runs --cursor " << page["next_cursor"].get<std::string>() << "\n";
  }
  return o.str();
}

std::string format_executions(const json& page) {
  std::ostringstream o;
  if (page["items"].empty()) return "no executions\n";
  for (const auto& e : page["items"]) {
    o << str(e, "id") << "  " << str(e, "campaign") << "  " << str(e, "status") << "  " << str(e, "created_at")
      << "  run " << str(e, "run_id");
    if (!str(e, "reason").empty()) o << "  (" << str(e, "reason") << ")";
    o << "\n";
  }
  // The filters are the caller's to repeat: the cursor alone continues the same listing only with them.
  if (page.contains("next_cursor") && !page["next_cursor"].is_null()) {
    o << "more: --cursor " << page["next_cursor"].get<std::string>() << " (with the same filters)\n";
  }
  return o.str();
}

std::string format_run(const json& r) {
  std::ostringstream o;
  o << "run " << str(r, "id") << "\n"
    << "  campaign   " << str(r, "campaign") << "  params " << r["params"].dump() << "\n"
    << "  status     " << str(r, "status") << "\n"
    << "  data       "
    << (r.value("simulated", false) ? "SIMULATED instruments (not a measurement of the real lab)"
                                    : "real instruments")
    << "\n"
    << "  created    " << str(r, "created_at") << "\n"
    << "  finished   " << str(r, "finished_at") << "\n";
  if (r.contains("summary") && !r["summary"].is_null()) o << "  summary    " << r["summary"].dump() << "\n";
  if (r.contains("error")) {
    o << "  error      " << r["error"].value("detail", std::string()) << "\n";
    if (r["error"].contains("hint")) o << "  hint       " << r["error"]["hint"].get<std::string>() << "\n";
  }
  if (r.contains("measurements")) {
    o << "  measurements (" << r["measurements"].size() << "):\n";
    for (const auto& m : r["measurements"]) {
      o << "    " << str(m, "step") << "  " << str(m, "instrument_id") << "  " << str(m, "quantity") << "  ";
      if (m["value"].is_number()) o << number(m["value"].get<double>()) << " " << str(m, "unit");
      o << "  " << str(m, "measured_at") << "\n";
    }
  }
  return o.str();
}

std::string format_execution(const json& e) {
  std::ostringstream o;
  o << "execution " << str(e, "id") << "  " << str(e, "campaign") << "  " << str(e, "status") << "  "
    << number(100.0 * e.value("progress", 0.0), 0) << "%  " << str(e, "step");
  if (!e.value("reason", std::string()).empty()) o << "  (" << e["reason"].get<std::string>() << ")";
  o << "\n";
  // Why a suspended execution waits; the crash-loop guard also says when it retries by itself.
  if (e.contains("suspension") && e["suspension"].is_object()) {
    const json& s = e["suspension"];
    o << "  suspended  " << str(s, "category");
    if (s.contains("retry_at")) o << ", retried by colorlabd at " << str(s, "retry_at") << " (retry " << str(s, "retry") << " of " << str(s, "retries") << ")";
    o << "\n";
    if (s.contains("problem") && s["problem"].contains("hint")) o << "  hint       " << str(s["problem"], "hint") << "\n";
  }
  return o.str();
}

std::string format_dry_run(const json& r) {
  std::ostringstream o;
  const json& e = r.value("estimate", json::object());
  o << "dry run of " << str(r, "campaign") << ": " << (r.value("ok", false) ? "OK" : "PROBLEMS") << ", " << str(r, "calls")
    << " lab calls, " << str(r, "measurements") << " measurements, " << str(r, "lamp_warmups") << " lamp warm-ups\n";
  const double scale = e.value("time_scale", 1.0);
  o << "  estimated duration: " << duration(e.value("lab_seconds", 0.0)) << " of lab time";
  if (scale != 1.0) o << " = " << duration(e.value("wall_seconds", 0.0)) << " at time scale ×" << number(scale, 0);
  o << " (" << number(100 * e.value("measured_share", 0.0), 0) << " % from this lab's measured timings)\n";
  if (e.value("operator_wait_s", 0.0) > 0) {
    o << "  of which up to " << duration(e.value("operator_wait_s", 0.0)) << " waiting for a person (each request's timeout)\n";
  }
  o << "  where the time goes:\n";
  int shown = 0;
  for (const auto& k : e.value("by_key", json::array())) {
    if (shown++ == 8) break;
    o << "    " << duration(k.value("lab_seconds", 0.0)) << "  " << str(k, "key") << " ×" << str(k, "calls") << "  ("
      << str(k, "source") << (k.contains("n") ? ", n = " + k["n"].dump() : std::string()) << ")\n";
  }
  for (const auto& i : r.value("instruments", json::array())) {
    o << "  " << str(i, "role") << ": " << (i["instrument"].is_null() ? "MISSING" : str(i, "instrument"))
      << (i.value("simulated", false) ? " (simulated)" : "") << "\n";
  }
  for (const auto& a : r.value("operator_actions", json::array())) {
    o << "  operator: " << str(a, "action") << " ×" << str(a, "count") << " by " << str(a, "by") << " — " << str(a, "prompt")
      << " (default " << str(a, "default") << " after " << duration(a.value("timeout_s", 0.0)) << ")\n";
  }
  const json& st = r.value("storage", json::object());
  o << "  storage: about " << number(st.value("estimated_bytes", 0.0) / 1e6, 1) << " MB";
  if (st.contains("available_bytes")) o << " of " << number(st["available_bytes"].get<double>() / 1e9, 1) << " GB free";
  o << "\n";
  for (const auto& p : r.value("problems", json::array())) o << "  PROBLEM (" << str(p, "kind") << "): " << str(p, "message") << "\n";
  if (r.contains("stopped_at")) o << "  the dry run stopped at line " << str(r["stopped_at"], "line") << "\n";
  return o.str();
}

std::string format_request(const json& r) {
  std::ostringstream o;
  o << "operator request " << str(r, "id") << " (" << str(r, "action") << "): " << str(r, "prompt") << "\n";
  if (r.contains("answer")) {
    o << "  answered " << str(r, "answer") << " by " << str(r, "answered_by") << "\n";
    return o.str();
  }
  std::string options;
  for (const auto& opt : r.value("options", json::array())) options += (options.empty() ? "" : " | ") + opt.get<std::string>();
  o << "  answer: colorlab answer " << str(r, "id") << " <" << options << ">   default " << str(r, "default")
    << " at " << str(r, "deadline") << "\n";
  return o.str();
}

std::string format_requests(const json& list) {
  if (!list.contains("items") || list["items"].empty()) return "no operator requests waiting\n";
  std::string out;
  for (const auto& r : list["items"]) out += format_request(r);
  return out;
}

// A sequence as GET /v1/campaigns lists it: its steps in order, what each takes from an earlier one,
// the parameters each is given and the small variant's.
std::string format_sequence(const json& c) {
  std::ostringstream o;
  o << str(c, "name") << "  (sequence, " << str(c, "origin") << ")\n    " << str(c, "description") << "\n";
  int n = 0;
  for (const auto& step : c.value("steps", json::array())) {
    o << "    " << ++n << ". " << str(step, "name");
    if (str(step, "campaign") != str(step, "name")) o << " (" << str(step, "campaign") << ")";
    if (step.contains("params") && !step["params"].empty()) o << "  " << step["params"].dump();
    if (step.contains("reference") && step["reference"].is_object()) {
      o << "  " << str(step["reference"], "param") << " = the run of " << str(step["reference"], "step");
    }
    o << "\n";
    const json small = c.value("small", json::object());
    if (small.contains(str(step, "name"))) o << "       --small: " << small[str(step, "name")].dump() << "\n";
  }
  o << "    colorlab run " << str(c, "name") << " [--small] [-p STEP.KEY=VALUE]   (queues every step)\n";
  return o.str();
}

std::string format_queue_group(const json& g) {
  std::ostringstream o;
  o << "group " << str(g, "id") << "  sequence " << str(g, "sequence") << "  " << str(g, "state") << "\n";
  for (const auto& item : g.value("items", json::array())) {
    o << "  " << str(item, "step") << "  " << str(item, "state");
    if (item["position"].is_number()) o << " at position " << item["position"].dump();
    o << "  item " << str(item, "id");
    if (item.contains("run_id") && item["run_id"].is_string()) o << "  run " << item["run_id"].get<std::string>();
    const json refs = item.value("param_refs", json::object());  // kept: items() of a temporary would dangle
    for (const auto& [param, ref] : refs.items()) {
      o << "  " << param << " ← " << ref.get<std::string>();
    }
    if (!item.value("reason", std::string()).empty()) o << "\n      " << item["reason"].get<std::string>();
    o << "\n";
  }
  // The daemon makes the study's report of these runs on request (a browser follows the 202s by itself).
  if (g.contains("links") && g["links"].contains("report")) o << "report  " << g["links"]["report"].get<std::string>() << "\n";
  return o.str();
}

std::string format_queue_item(const json& q) {
  std::ostringstream o;
  o << str(q, "id") << "  " << str(q, "campaign") << "  " << str(q, "state");
  if (q.contains("position") && q["position"].is_number()) o << " at position " << q["position"].dump();
  o << "  on failure: " << str(q, "on_failure");
  if (q.contains("params") && !q["params"].empty()) o << "  params " << q["params"].dump();
  if (q.contains("execution_id") && !q["execution_id"].is_null()) o << "\n    execution " << str(q, "execution_id");
  if (!q.value("reason", std::string()).empty()) o << "\n    " << q["reason"].get<std::string>();
  o << "\n";
  return o.str();
}

std::string format_queue(const json& queue) {
  std::ostringstream o;
  o << "queue " << str(queue, "state");
  if (!queue.value("reason", std::string()).empty()) o << " — " << queue["reason"].get<std::string>();
  if (queue.value("autostart", false)) o << "  (autostart)";
  o << "\n";
  const auto& current = queue["current"];
  if (current.is_object()) {
    o << "  now  " << str(current, "id") << "  " << str(current, "campaign") << "  execution "
      << str(current, "execution_id") << " " << str(current, "execution_status") << "\n";
  }
  if (queue.contains("waiting_for") && !queue["waiting_for"].is_null()) {
    o << "  waiting for execution " << str(queue, "waiting_for") << " to end\n";
  }
  bool any = false;
  for (const auto& q : queue["items"]) {
    if (q.value("state", std::string()) != "queued") continue;
    any = true;
    o << "  " << str(q, "position") << "    " << str(q, "id") << "  " << str(q, "campaign") << "  on failure: "
      << str(q, "on_failure");
    if (!q["params"].empty()) o << "  " << q["params"].dump();
    o << "\n";
  }
  if (!any) o << "  nothing queued\n";
  if (queue.contains("history") && !queue["history"].empty()) {
    o << "recent:\n";
    for (const auto& q : queue["history"]) {
      o << "  " << str(q, "id") << "  " << str(q, "campaign") << "  " << str(q, "state") << "  " << str(q, "updated_at");
      if (!q.value("reason", std::string()).empty()) o << "  (" << q["reason"].get<std::string>() << ")";
      o << "\n";
    }
  }
  return o.str();
}

}  // namespace colorlab::cli
