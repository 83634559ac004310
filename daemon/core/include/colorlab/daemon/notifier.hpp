#pragma once
// Tells the operator when an unattended night needs a person: an execution suspended, caught in a
// crash loop, or failed ([notify] in colorlabd.toml, docs/configuration.md "Notifications"). Each
// notification is one JSON document, handed to a configured command on its stdin (argv, no shell)
// and/or POSTed to a webhook. Delivery runs on a thread of its own with a bounded queue and a
// per-delivery timeout: the io thread only enqueues, and a slow or failing receiver is logged, never
// waited for by a campaign, never able to lose a measurement.
#include <condition_variable>
#include <deque>
#include <mutex>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "colorlab/daemon/config.hpp"

namespace colorlab::daemon {

class Notifier {
 public:
  explicit Notifier(NotifyConfig config);
  // Waits for the delivery under way (bounded by timeout_s); what is still queued is logged and dropped.
  ~Notifier();
  Notifier(const Notifier&) = delete;
  Notifier& operator=(const Notifier&) = delete;

  // From any thread, without blocking. `event` is suspended, crash-loop or failed; `details` (the
  // execution's id, campaign, reason, problem, …) goes into the document beside event, time and host.
  // Events not configured are ignored; beyond kMaxQueued waiting ones the newest is dropped and logged.
  void notify(const std::string& event, const nlohmann::json& details);

  static constexpr std::size_t kMaxQueued = 64;

 private:
  void work();
  void deliver(const nlohmann::json& document);
  void run_command(const std::string& body, const std::string& event);
  void post_webhook(const std::string& body);

  NotifyConfig config_;
  std::string host_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<nlohmann::json> queue_;
  bool stopping_ = false;
  std::thread worker_;
};

}  // namespace colorlab::daemon
