#pragma once
// Runs a driver coroutine on the io_context that also drives the simulator, with a hard limit so a
// driver bug shows up as a failed test, never as a hung one.
#include <chrono>
#include <future>
#include <stdexcept>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/use_future.hpp>

namespace colorlab::test {

template <class T>
T run(boost::asio::io_context& io, boost::asio::awaitable<T> aw, std::chrono::seconds limit = std::chrono::seconds(60)) {
  auto fut = boost::asio::co_spawn(io, std::move(aw), boost::asio::use_future);
  auto deadline = std::chrono::steady_clock::now() + limit;
  while (fut.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    if (io.stopped()) io.restart();
    io.run_one_for(std::chrono::milliseconds(50));
    if (std::chrono::steady_clock::now() > deadline) throw std::runtime_error("driver operation hung past the test's limit");
  }
  return fut.get();
}

// Lets the simulator's side finish what is queued (e.g. a last reply) without a driver call pending.
inline void settle(boost::asio::io_context& io, std::chrono::milliseconds d) {
  auto until = std::chrono::steady_clock::now() + d;
  while (std::chrono::steady_clock::now() < until) {
    if (io.stopped()) io.restart();
    io.run_one_for(std::chrono::milliseconds(10));
  }
}

}  // namespace colorlab::test
