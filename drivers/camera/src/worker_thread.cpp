#include "colorlab/drivers/camera/worker_thread.hpp"

#include <pthread.h>

#include "colorlab/core/thread_priority.hpp"

namespace colorlab::drivers::camera {

WorkerThread::WorkerThread(std::string name) : name_(std::move(name)) {
  thread_ = std::thread([this] { run(); });
  // Named so a stuck device call shows up by name in gdb, top -H and core dumps.
  pthread_setname_np(thread_.native_handle(), name_.substr(0, 15).c_str());
}

WorkerThread::~WorkerThread() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void WorkerThread::post(std::function<void()> task) {
  {
    std::lock_guard lock(mutex_);
    tasks_.push_back(std::move(task));
  }
  wake_.notify_one();
}

void WorkerThread::run() {
  // A camera's device thread captures and transfers full-size frames (the simulated DSLR reads them from its card
  // folder): heavy, so below the daemon's answering threads like the decode thread (core/thread_priority.hpp).
  core::lower_this_thread(core::heavy_thread_nice(), name_);
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stopping_ || !tasks_.empty(); });
    if (tasks_.empty()) return;  // stopping and drained
    auto task = std::move(tasks_.front());
    tasks_.pop_front();
    lock.unlock();
    task();  // tasks report their own failures through futures or callbacks
    lock.lock();
  }
}

}  // namespace colorlab::drivers::camera
