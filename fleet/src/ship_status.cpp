#include "colorlab/fleet/ship_status.hpp"

#include <fstream>

#include <nlohmann/json.hpp>

#include "colorlab/core/ids.hpp"
#include "colorlab/core/log.hpp"

namespace colorlab::fleet {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

json previous(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return json::object();
  json j = json::parse(in, nullptr, false);
  return j.is_object() ? j : json::object();
}

// Temporary file and rename: colorlabd never reads half a file. No fsync: a status lost to a power cut is
// rewritten by the next cycle, and the position that matters for retention has its own durable note.
void write(const fs::path& file, const json& status) {
  try {
    fs::create_directories(file.parent_path());
    const fs::path tmp = file.string() + ".tmp";
    {
      std::ofstream out(tmp, std::ios::trunc);
      out << status.dump(2) << "\n";
      out.flush();
      if (!out) throw std::runtime_error("cannot write " + tmp.string());
    }
    fs::rename(tmp, file);
  } catch (const std::exception& e) {
    log::warning("ship", std::string("cannot record the agent's status: ") + e.what());
  }
}

}  // namespace

void note_cycle_ok(const ShipConfig& c, const CycleReport& r) {
  const fs::path file = ship_status_file(c);
  json s = previous(file);
  const std::string now = now_iso8601();
  s["updated_at"] = now;
  s["ok"] = r.divergences.empty();
  s["position"] = r.position_after;
  s["last_cycle"] = {{"runs_shipped", r.runs_shipped}, {"measurements", r.measurements}, {"blobs_uploaded", r.blobs_uploaded}};
  if (r.divergences.empty()) {
    s["last_success_at"] = now;
  } else {
    const auto& d = r.divergences.front();
    s["last_error"] = {{"message", "run " + d.run_id + " differs between the bench and central (digest mismatch); "
                                                       "shipping stops before it"},
                       {"hint", "colorlab-ship verify; central's ship_problems table has both digests"},
                       {"at", now}};
  }
  if (!s.contains("last_error")) s["last_error"] = nullptr;
  if (!s.contains("last_success_at")) s["last_success_at"] = nullptr;
  write(file, s);
}

void note_cycle_failed(const ShipConfig& c, const std::string& message, const std::string& hint) {
  const fs::path file = ship_status_file(c);
  json s = previous(file);
  const std::string now = now_iso8601();
  s["updated_at"] = now;
  s["ok"] = false;
  s["last_error"] = {{"message", message}, {"hint", hint}, {"at", now}};
  if (!s.contains("last_success_at")) s["last_success_at"] = nullptr;
  if (!s.contains("position")) s["position"] = nullptr;
  write(file, s);
}

}  // namespace colorlab::fleet
