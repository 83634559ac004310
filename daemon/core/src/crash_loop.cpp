#include "colorlab/daemon/crash_loop.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <vector>

#include "colorlab/protocol/problem.hpp"

namespace colorlab::daemon {

using nlohmann::json;

double CrashLoopPolicy::backoff(int round) const {
  if (round < 1) round = 1;
  // 2^(round − 1) overflows nothing that matters: the cap is reached within a few dozen rounds.
  const double raw = backoff_s * std::pow(2.0, std::min(round - 1, 60));
  return std::min(raw, std::max(backoff_max_s, backoff_s));
}

CrashLoopVerdict judge_crash_loop(const CrashLoopPolicy& policy, int attempts) {
  CrashLoopVerdict v;
  if (attempts <= policy.max_resume_attempts) return v;
  v.round = attempts - policy.max_resume_attempts;
  if (v.round > policy.retries) {
    v.kind = CrashLoopVerdict::Kind::give_up;
    return v;
  }
  v.kind = CrashLoopVerdict::Kind::suspend;
  v.backoff_s = policy.backoff(v.round);
  return v;
}

json crash_loop_problem(const std::string& detail, const std::string& hint) {
  protocol::Problem p;
  p.status = 503;
  p.code = kCrashLoopCategory;
  p.title = "Crash loop";
  p.detail = detail;
  p.hint = hint;
  p.category = protocol::ProblemCategory::undefined_execution;
  return p.to_json();
}

bool is_crash_loop(const json& suspension) {
  return suspension.is_object() && suspension.value("category", std::string()) == kCrashLoopCategory;
}

double seconds_until(const std::string& retry_at, double backoff_s, std::chrono::system_clock::time_point now) {
  std::tm tm{};
  double seconds = 0;
  // "2026-11-22T00:01:48.123Z" (colorlab::iso8601_utc)
  if (std::sscanf(retry_at.c_str(), "%d-%d-%dT%d:%d:%lfZ", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour,
                  &tm.tm_min, &seconds) != 6) {
    return backoff_s;
  }
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  tm.tm_sec = 0;
  const std::time_t whole = ::timegm(&tm);
  if (whole == static_cast<std::time_t>(-1)) return backoff_s;
  const double at = static_cast<double>(whole) + seconds;
  const double now_s = std::chrono::duration<double>(now.time_since_epoch()).count();
  return std::clamp(at - now_s, 0.0, backoff_s);
}

int max_starts_within(const CrashLoopPolicy& policy, double interval_s, double restart_s) {
  // Two episodes back to back, each crash at once after its start (the worst case for a rate limit).
  std::vector<double> starts{0};  // the daemon's start that runs the first doomed step
  double t = 0;
  for (int episode = 0; episode < 2; ++episode) {
    // The restarts that count resume attempts 1..max, then the one where the guard trips.
    for (int a = 1; a <= policy.max_resume_attempts + 1; ++a) starts.push_back(t += restart_s);
    // Each back-off retry dies and is restarted; the restart after the last one gives up, and the
    // queue's next run (starting in that same process) is the next episode's first crash.
    for (int round = 1; round <= policy.retries; ++round) starts.push_back(t += policy.backoff(round) + restart_s);
  }
  int most = 0;
  for (std::size_t i = 0; i < starts.size(); ++i) {
    int n = 0;
    for (std::size_t j = i; j < starts.size() && starts[j] < starts[i] + interval_s; ++j) ++n;
    most = std::max(most, n);
  }
  return most;
}

}  // namespace colorlab::daemon
