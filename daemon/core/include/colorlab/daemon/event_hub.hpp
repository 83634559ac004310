#pragma once
// Tells live event streams that the event log grew. One thread watches the log's newest seq
// through its own read connection (the writer is never asked), and wakes every waiting stream on
// its own executor. Streams then read the new events themselves, from their own connections: the
// hub holds no events, so a slow or stalled stream cannot make it grow.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <thread>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/awaitable.hpp>
#include <boost/asio/steady_timer.hpp>

namespace colorlab::daemon {

class EventHub {
 public:
  // `latest_seq` is called on the hub's own thread only.
  EventHub(std::function<std::int64_t()> latest_seq, std::chrono::milliseconds poll_interval);
  ~EventHub();
  EventHub(const EventHub&) = delete;
  EventHub& operator=(const EventHub&) = delete;

  void start();
  void stop();
  std::int64_t latest() const { return latest_.load(); }
  // Returns true once latest() > seq, false when `timeout` passes first (or the hub stops).
  boost::asio::awaitable<bool> wait_beyond(std::int64_t seq, std::chrono::milliseconds timeout);
  std::size_t waiting() const;
  bool stopped() const;

 private:
  // An entry lives no longer than its waiting coroutine's frame (wait_beyond erases it however the frame ends), so
  // its executor and timer never outlive their io_context.
  struct Waiter {
    boost::asio::any_io_executor executor;
    std::shared_ptr<boost::asio::steady_timer> timer;
  };
  void run();
  void wake_all();

  std::function<std::int64_t()> latest_seq_;
  std::chrono::milliseconds interval_;
  std::atomic<std::int64_t> latest_{0};
  mutable std::mutex mutex_;
  std::list<Waiter> waiters_;
  std::condition_variable stop_signal_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace colorlab::daemon
