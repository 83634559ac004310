#pragma once
// Drives a test's io_context until a condition holds, with a bound so a lost handler fails the test with the
// thing it waited for instead of hanging it (worker_pool_test, thread_priority_test).
#include <gtest/gtest.h>

#include <chrono>

#include <boost/asio/io_context.hpp>

namespace colorlab::testing {

// A bound, not a measurement: 60 s is far beyond any handler these tests wait for, on a slow machine too. A fatal
// failure returns from here only: wrap the call in ASSERT_NO_FATAL_FAILURE to stop the test there.
template <class Pred>
void run_until(boost::asio::io_context& io, Pred done, const char* what) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!done()) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "timed out waiting for " << what;
    io.restart();
    io.run_one_for(std::chrono::milliseconds(50));
  }
}

}  // namespace colorlab::testing
