// GET /v1/shipping: what colorlab-ship has not shipped yet and what its last cycle said. Everything comes from the
// bench itself — the event log (colorlab.db) and the two files the agent writes under <state_dir>/ship/ — so the
// daemon never talks to central or waits on the network to answer (docs/fleet.md, "Lag").
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/daemon/blob_service.hpp"
#include "colorlab/protocol/api.hpp"
#include "colorlab/store/ship_log.hpp"
#include "handlers.hpp"

namespace colorlab::daemon::routes {

using nlohmann::json;
namespace fs = std::filesystem;

namespace {

// Seconds since the epoch of "2026-11-29T05:44:08.123Z" (colorlab::iso8601_utc), or NaN.
double epoch_seconds(const std::string& iso) {
  std::tm tm{};
  double seconds = 0;
  if (std::sscanf(iso.c_str(), "%d-%d-%dT%d:%d:%lfZ", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour, &tm.tm_min,
                  &seconds) != 6) {
    return std::nan("");
  }
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  const std::time_t whole = ::timegm(&tm);
  if (whole == static_cast<std::time_t>(-1)) return std::nan("");
  return static_cast<double>(whole) + seconds;
}

// Seconds from `iso` to now, to the millisecond; null when the time is missing or unreadable.
json seconds_since(const std::string& iso, double now) {
  const double t = epoch_seconds(iso);
  if (std::isnan(t)) return nullptr;
  return std::round(std::max(0.0, now - t) * 1000) / 1000;
}

// The agent's note of what central holds; 0 when it never shipped (as blob retention reads it).
std::int64_t shipped_position(const fs::path& note) {
  std::ifstream in(note);
  long long v = 0;
  if (!in || !(in >> v) || v < 0) return 0;
  return v;
}

json agent_status(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return nullptr;
  json j = json::parse(in, nullptr, false);
  if (!j.is_object()) return json{{"unreadable", file.string()}};
  return j;
}

}  // namespace

HttpResponse get_shipping(ApiContext& ctx, const HttpRequest&, const PathParams&) {
  if (!ctx.blobs) throw Error(ErrorClass::internal, "GET /v1/shipping without the blob service");
  // The blob store lives in <state_dir>/blobs, beside the agent's notes (retention reads them the same way).
  const fs::path state_dir = ctx.blobs->files().root().parent_path();
  const fs::path dir = state_dir / "ship";
  const double now = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  const std::int64_t position = shipped_position(dir / "shipped-position");
  json agent = agent_status(dir / "status.json");
  // A bench that does not ship has nothing to count, and the console asks every few seconds: without a position
  // the backlog would read the whole event log each time.
  if (!ctx.blobs->config().keep_unshipped && agent.is_null()) {
    return HttpResponse::json(200, json{
                                       {"enabled", false},
                                       {"shipped_position", position},
                                       {"last_event", nullptr},
                                       {"lag", nullptr},
                                       {"agent", nullptr},
                                       {"last_error", nullptr},
                                       {"agent_seen_s_ago", nullptr},
                                   });
  }
  // A read-only connection of its own: the pool's connections belong to their threads' snapshots, and this one
  // reads the log after the agent's position only.
  store::Database db((state_dir / std::string(protocol::kDatabaseName)).string(), true);
  db.exec("PRAGMA busy_timeout = 5000");
  db.exec("PRAGMA query_only = ON");
  const auto backlog = store::ShipLog(db).backlog(position);

  json lag{{"unshipped_runs", backlog.runs},
           {"oldest_unshipped_run", backlog.oldest_run_id.empty() ? json(nullptr) : json(backlog.oldest_run_id)},
           {"oldest_unshipped_status", backlog.oldest_status.empty() ? json(nullptr) : json(backlog.oldest_status)},
           {"oldest_unshipped_ended_at", backlog.oldest_ended_at.empty() ? json(nullptr) : json(backlog.oldest_ended_at)},
           // How long the oldest unshipped run has waited since it ended; 0 when nothing waits.
           {"age_s", backlog.runs == 0 ? json(0) : seconds_since(backlog.oldest_ended_at, now)}};
  json out{{"enabled", ctx.blobs->config().keep_unshipped},
           {"shipped_position", position},
           {"last_event", backlog.last_event},
           {"lag", lag},
           {"agent", agent},
           {"last_error", agent.is_object() && agent.contains("last_error") ? agent["last_error"] : json(nullptr)},
           // A silent agent (stopped, or never started) is the thing to alert on beside the lag.
           {"agent_seen_s_ago", agent.is_object() && agent.contains("updated_at") && agent["updated_at"].is_string()
                                    ? seconds_since(agent["updated_at"].get<std::string>(), now)
                                    : json(nullptr)}};
  return HttpResponse::json(200, out);
}

}  // namespace colorlab::daemon::routes
