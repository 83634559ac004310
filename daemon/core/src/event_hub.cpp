#include "colorlab/daemon/event_hub.hpp"

#include <optional>

#include <boost/asio/post.hpp>
#include <boost/asio/redirect_error.hpp>
#include <boost/asio/this_coro.hpp>
#include <boost/asio/use_awaitable.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"

namespace colorlab::daemon {

namespace asio = boost::asio;

EventHub::EventHub(std::function<std::int64_t()> latest_seq, std::chrono::milliseconds poll_interval)
    : latest_seq_(std::move(latest_seq)), interval_(poll_interval) {}

EventHub::~EventHub() { stop(); }

void EventHub::start() {
  if (thread_.joinable()) return;
  latest_ = latest_seq_();
  thread_ = std::thread([this] { run(); });
}

void EventHub::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  stop_signal_.notify_all();
  if (thread_.joinable()) thread_.join();
  wake_all();
}

void EventHub::run() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    lock.unlock();
    std::int64_t seq = latest_.load();
    try {
      seq = latest_seq_();
    } catch (const Error& e) {
      log::warning("events", std::string("cannot read the event log's newest entry: ") + e.what());
    }
    if (seq > latest_.load()) {
      latest_ = seq;
      wake_all();
    }
    lock.lock();
    stop_signal_.wait_for(lock, interval_, [this] { return stopping_; });
  }
}

void EventHub::wake_all() {
  std::lock_guard lock(mutex_);
  // Each timer is cancelled on its own executor: Asio timers are not safe to touch from two threads.
  for (auto& w : waiters_) asio::post(w.executor, [timer = w.timer] { timer->cancel(); });
}

asio::awaitable<bool> EventHub::wait_beyond(std::int64_t seq, std::chrono::milliseconds timeout) {
  if (latest_.load() > seq) co_return true;
  auto executor = co_await asio::this_coro::executor;
  auto timer = std::make_shared<asio::steady_timer>(executor, timeout);
  // Erased however the wait ends, also when the stream's io_context destroys this coroutine without resuming it
  // (colorlabd stopping with a follower connected): an entry left behind would hold that io_context's executor and
  // timer past its services' end (ASan's heap-use-after-free at exit).
  struct Registration {
    EventHub& hub;
    std::list<Waiter>::iterator me;
    ~Registration() {
      std::lock_guard lock(hub.mutex_);
      hub.waiters_.erase(me);
    }
  };
  std::optional<Registration> registered;
  {
    std::lock_guard lock(mutex_);
    if (stopping_) co_return false;
    // Made in place: a moved-from temporary's destructor would erase the entry at once.
    registered.emplace(*this, waiters_.insert(waiters_.end(), Waiter{executor, timer}));
  }
  // Registered before this second look: a wake between the first look and now is not missed.
  if (latest_.load() <= seq) {
    boost::system::error_code ec;
    co_await timer->async_wait(asio::redirect_error(asio::use_awaitable, ec));
  }
  registered.reset();
  co_return latest_.load() > seq;
}

bool EventHub::stopped() const {
  std::lock_guard lock(mutex_);
  return stopping_;
}

std::size_t EventHub::waiting() const {
  std::lock_guard lock(mutex_);
  return waiters_.size();
}

}  // namespace colorlab::daemon
