#include "follow.hpp"

#include <chrono>
#include <cmath>
#include <iostream>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include <unistd.h>

#include "colorlab/client/sse.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/protocol/states.hpp"
#include "format.hpp"

namespace colorlab::cli {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

bool terminal(const json& e) {
  auto s = protocol::execution_status_from_string(e.value("status", std::string()));
  return s && protocol::is_terminal(*s);
}

std::string eta_text(double seconds) {
  const long s = std::lround(seconds);
  std::ostringstream o;
  if (s >= 3600) o << s / 3600 << "h " << (s % 3600) / 60 << "m";
  else if (s >= 60) o << s / 60 << "m " << s % 60 << "s";
  else o << s << "s";
  return o.str();
}

class Progress {
 public:
  Progress(json execution, bool quiet) : e_(std::move(execution)), quiet_(quiet), tty_(::isatty(2) == 1) {}

  json& execution() { return e_; }

  void update(const json& fields) {
    for (const char* k : {"status", "progress", "step", "reason", "error"}) {
      if (fields.contains(k)) e_[k] = fields[k];
    }
    const double p = e_.value("progress", 0.0);
    if (!start_ && p > 0 && e_.value("status", std::string()) == "running") start_ = {Clock::now(), p};
    show();
  }

  void request(const json& r) {
    if (quiet_ || !shown_requests_.insert(r.value("id", std::string())).second) return;
    clear_bar();
    std::cerr << format_request(r);
    show();
  }

  void finish() {
    if (quiet_) return;
    clear_bar();
    const std::string line = format_execution(e_);
    if (line != last_line_) std::cerr << line;
  }

 private:
  // Seconds left from the rate seen since the first progress this client witnessed (the daemon's own
  // dry-run estimate knows the campaign; this knows the night's real pace).
  std::optional<double> eta() const {
    if (!start_) return std::nullopt;
    const double p = e_.value("progress", 0.0);
    const double dt = std::chrono::duration<double>(Clock::now() - start_->first).count();
    if (p <= start_->second || dt <= 0) return std::nullopt;
    return (1.0 - p) / ((p - start_->second) / dt);
  }

  void show() {
    if (quiet_) return;
    if (!tty_) {  // a log or a pipe: one line per change of status, step or whole percent
      const std::string line = format_execution(e_);
      if (line != last_line_) std::cerr << line;
      last_line_ = line;
      return;
    }
    const double p = std::clamp(e_.value("progress", 0.0), 0.0, 1.0);
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(p * kWidth);
    std::ostringstream o;
    o << "\r\033[K" << e_.value("campaign", std::string()) << " [" << std::string(filled, '#')
      << std::string(kWidth - filled, '-') << "] " << std::lround(100 * p) << "%  " << e_.value("step", std::string());
    const std::string status = e_.value("status", std::string());
    if (status != "running") {
      o << "  (" << status;
      if (!e_.value("reason", std::string()).empty()) o << ": " << e_["reason"].get<std::string>();
      o << ")";
    } else if (auto left = eta()) {
      o << "  ETA " << eta_text(*left);
    }
    std::cerr << o.str() << std::flush;
    bar_shown_ = true;
  }

  void clear_bar() {
    if (bar_shown_) std::cerr << "\r\033[K" << std::flush;
    bar_shown_ = false;
  }

  json e_;
  bool quiet_, tty_;
  bool bar_shown_ = false;
  std::string last_line_;
  std::optional<std::pair<Clock::time_point, double>> start_;
  std::set<std::string> shown_requests_;
};

}  // namespace

json follow_execution(const client::ApiClient& api, json execution, bool quiet) {
  const std::string id = execution["id"];
  Progress progress(std::move(execution), quiet);
  std::string last_event_id;
  for (int reconnects = 0;; ++reconnects) {
    bool done = false;
    client::SseParser parser([&](const client::SseEvent& ev) {
      last_event_id = ev.id;
      json data = json::parse(ev.data, nullptr, false);
      if (data.is_discarded()) return true;
      if (ev.event == "snapshot") {
        bool listed = false;
        for (const auto& e : data.value("executions", json::array())) {
          if (e.value("id", std::string()) == id) {
            listed = true;
            progress.update(e);
          }
        }
        for (const auto& r : data.value("requests", json::array())) {
          if (r.value("execution_id", std::string()) == id) progress.request(r);
        }
        // Snapshots list unfinished executions only: one that is absent has ended before we listened.
        if (!listed) {
          progress.update(api.get("/v1/executions/" + id));
          done = terminal(progress.execution());
        }
        return !done;
      }
      const json& p = data.value("payload", json::object());
      if (ev.event == "progress" && p.value("execution_id", std::string()) == id) {
        progress.update(p);
      } else if (ev.event == "execution" && p.value("execution_id", p.value("id", std::string())) == id) {
        progress.update(p);
        done = terminal(progress.execution());
      } else if (ev.event == "operator" && p.value("event", std::string()) == "posted" && p.contains("request") &&
                 p["request"].value("execution_id", std::string()) == id) {
        progress.request(p["request"]);
      }
      return !done;
    });
    std::map<std::string, std::string> headers;
    if (!last_event_id.empty()) headers["Last-Event-ID"] = last_event_id;
    try {
      api.stream(
          "/v1/events/stream", [&](std::string_view bytes) { return parser.feed(bytes); }, headers);
    } catch (const Error& e) {
      // A dropped link (the daemon restarting, a network blip): resume from the last event seen.
      if (e.cls() != ErrorClass::no_comms || reconnects >= 30) throw;
      std::this_thread::sleep_for(std::chrono::seconds(1));
    }
    if (done) break;
    // The stream ended without the end of the execution (a daemon shutting down): ask, then listen again.
    try {
      json now = api.get("/v1/executions/" + id);
      progress.update(now);
      if (terminal(now)) break;
    } catch (const Error&) {
      if (reconnects >= 30) throw;
      std::this_thread::sleep_for(std::chrono::seconds(1));
    }
  }
  progress.finish();
  return progress.execution();
}

}  // namespace colorlab::cli
