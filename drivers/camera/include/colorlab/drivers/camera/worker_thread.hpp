#pragma once
// A thread that owns a device and runs every call to it in submission order. Callers on an Asio
// event loop (or anywhere else) post work and get a future or a callback, so nothing they do
// blocks on a slow camera; libraries that are not thread-safe (libgphoto2) stay on one thread.
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <type_traits>

namespace colorlab::drivers::camera {

class WorkerThread {
 public:
  explicit WorkerThread(std::string name);
  ~WorkerThread();  // runs what is queued, then joins
  WorkerThread(const WorkerThread&) = delete;
  WorkerThread& operator=(const WorkerThread&) = delete;

  void post(std::function<void()> task);

  template <class F>
  auto submit(F&& f) -> std::future<std::invoke_result_t<F>> {
    using R = std::invoke_result_t<F>;
    auto task = std::make_shared<std::packaged_task<R()>>(std::forward<F>(f));
    auto result = task->get_future();
    post([task] { (*task)(); });
    return result;
  }

  bool on_this_thread() const { return std::this_thread::get_id() == thread_.get_id(); }
  const std::string& name() const { return name_; }

 private:
  void run();

  std::string name_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> tasks_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace colorlab::drivers::camera
