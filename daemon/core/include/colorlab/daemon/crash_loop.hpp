#pragma once
// The crash-loop guard's policy (docs/campaigns.md, "Crash loops"). An execution whose step keeps
// killing colorlabd — it stopped more than max_resume_attempts times in a row during one step without
// committing it — is no instrument's failure and must not end an unattended night: it is suspended
// with the category `crash-loop`, and colorlabd itself retries it after a back-off that doubles from
// backoff_s up to backoff_max_s. A crash after the last of `retries` retries ends the execution
// (finished_error, problem code crash-loop), so its queue item's on_failure decides what the night does
// next. Each back-off retry that dies again counts one more resume attempt, so the round needs no
// counter of its own: round = resume attempts − max_resume_attempts.
#include <chrono>
#include <string>

#include <nlohmann/json.hpp>

namespace colorlab::daemon {

struct CrashLoopPolicy {
  int max_resume_attempts = 3;
  double backoff_s = 60;
  double backoff_max_s = 1800;
  int retries = 6;

  // The wait before retry `round` (1-based): backoff_s · 2^(round − 1), at most backoff_max_s.
  double backoff(int round) const;
};

struct CrashLoopVerdict {
  enum class Kind {
    resume,
    suspend,
    give_up
  } kind = Kind::resume;
  int round = 0;         // 1.. for suspend; retries + 1 for give_up
  double backoff_s = 0;  // for suspend
};

// What to do with an execution a restarted daemon finds running, after `attempts` resumes in a row
// that committed nothing (this one included).
CrashLoopVerdict judge_crash_loop(const CrashLoopPolicy& policy, int attempts);

inline constexpr const char* kCrashLoopCategory = "crash-loop";

// problem+json of the guard: code crash-loop, title "Crash loop", status 503 (try again later).
nlohmann::json crash_loop_problem(const std::string& detail, const std::string& hint);
bool is_crash_loop(const nlohmann::json& suspension);

// Seconds from `now` until the ISO-8601 UTC time `retry_at`, kept within [0, backoff_s]: a wall clock
// stepped back while colorlabd was down must not stretch a back-off, one stepped forward ends it.
// An unreadable time counts as the whole back-off.
double seconds_until(const std::string& retry_at, double backoff_s, std::chrono::system_clock::time_point now);

// The most starts of colorlabd that fall within any `interval_s` while the guard deals with a step that
// kills the daemon at once every time, the next queued run doing the same right after (systemd
// restarting it `restart_s` after each crash). The shipped unit's StartLimitBurst must not be below it
// for StartLimitIntervalSec, or systemd gives up before the guard's back-off matters.
int max_starts_within(const CrashLoopPolicy& policy, double interval_s, double restart_s);

}  // namespace colorlab::daemon
