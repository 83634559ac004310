// The worker pool (issue 27): results come back on the io thread, a full queue refuses with a typed
// error, exceptions arrive as colorlab::Error, and shutdown cancels what waits and lets the running
// job finish. Jobs are held by futures the test releases: nothing here depends on timing.
#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <optional>
#include <thread>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/use_future.hpp>

#include "colorlab/daemon/worker_pool.hpp"
#include "run_until.hpp"

namespace colorlab::daemon {
namespace {

namespace asio = boost::asio;
using nlohmann::json;
using testing::run_until;

struct Outcome {
  std::optional<json> result;
  std::optional<Error> error;
  std::thread::id on;
  bool arrived = false;
};

std::function<void(std::exception_ptr, json)> into(Outcome& out) {
  return [&out](std::exception_ptr e, json j) {
    out.arrived = true;
    out.on = std::this_thread::get_id();
    if (e) {
      try {
        std::rethrow_exception(e);
      } catch (const Error& err) {
        out.error = err;
      }
    } else {
      out.result = std::move(j);
    }
  };
}

TEST(WorkerPool, RunsTheJobOffTheIoThreadAndPostsTheResultBack) {
  asio::io_context io;
  WorkerPool pool(io.get_executor(), WorkerPoolOptions{1, 4, {}});
  std::thread::id job_thread;
  Outcome out;
  pool.submit(
      "a fit", [&] {
        job_thread = std::this_thread::get_id();
        return json{{"de00", 1.5}};
      },
      into(out));
  run_until(
      io, [&] { return out.arrived; }, "the job's result");
  ASSERT_TRUE(out.result) << (out.error ? out.error->what() : "");
  EXPECT_EQ((*out.result)["de00"], 1.5);
  EXPECT_NE(job_thread, std::this_thread::get_id()) << "the job ran on the io thread";
  EXPECT_EQ(out.on, std::this_thread::get_id()) << "the result was not handed back on the io thread";
}

TEST(WorkerPool, AFullQueueRefusesWithATypedErrorAndAlwaysAdmissionStillQueues) {
  asio::io_context io;
  WorkerPool pool(io.get_executor(), WorkerPoolOptions{1, 2, {}});
  std::promise<void> release;
  std::promise<void> started;
  auto gate = release.get_future().share();
  Outcome first, second, third, always;
  pool.submit(
      "the held job", [&, gate] {
        started.set_value();
        gate.wait();
        return json(1);
      },
      into(first));
  // Once the worker holds the first job, the queue is empty: two places, then refusals.
  ASSERT_EQ(started.get_future().wait_for(std::chrono::seconds(60)), std::future_status::ready) << "the worker never started";
  pool.submit(
      "two", [] { return json(2); }, into(second));
  pool.submit(
      "three", [] { return json(3); }, into(third));
  EXPECT_EQ(pool.queued(), 2u);
  EXPECT_EQ(pool.running(), 1u);
  try {
    pool.submit(
        "a fourth", [] { return json(4); }, [](std::exception_ptr, json) {});
    FAIL() << "a full queue took a job";
  } catch (const WorkerPoolFull& e) {
    EXPECT_NE(std::string(e.what()).find("a fourth"), std::string::npos) << e.what();
    EXPECT_FALSE(e.hint().empty());
    EXPECT_GT(e.retry_after_s(), 0);
  }
  EXPECT_THROW(pool.admit("a dry run"), WorkerPoolFull);
  pool.submit(
      "a campaign's fit", [] { return json(5); }, into(always), Admission::always);
  release.set_value();
  run_until(
      io, [&] { return first.arrived && second.arrived && third.arrived && always.arrived; }, "every result");
  EXPECT_EQ(first.result, json(1));
  EXPECT_EQ(second.result, json(2));
  EXPECT_EQ(third.result, json(3));
  EXPECT_EQ(always.result, json(5));
}

TEST(WorkerPool, AnAdmissionHoldsAPlaceUntilItsHandleIsDropped) {
  asio::io_context io;
  WorkerPool pool(io.get_executor(), WorkerPoolOptions{1, 1, {}});
  auto place = pool.admit("a dry run");
  EXPECT_THROW(pool.submit(
                   "a dry run's rival", [] { return json(1); }, [](std::exception_ptr, json) {}),
               WorkerPoolFull);
  EXPECT_THROW(pool.admit("another dry run"), WorkerPoolFull);
  place.reset();
  Outcome out;
  EXPECT_NO_THROW(pool.submit(
      "a dry run's rival", [] { return json(1); }, into(out)));
  run_until(
      io, [&] { return out.arrived; }, "the result");
  EXPECT_EQ(out.result, json(1));
}

TEST(WorkerPool, ExceptionsArriveAsTypedErrors) {
  asio::io_context io;
  WorkerPool pool(io.get_executor(), WorkerPoolOptions{2, 4, {}});
  Outcome typed, foreign;
  pool.submit(
      "a fit", []() -> json { throw Error(ErrorClass::bad_data, "too few patches"); }, into(typed));
  pool.submit(
      "a fit", []() -> json { throw std::runtime_error("Eigen gave up"); }, into(foreign));
  run_until(
      io, [&] { return typed.arrived && foreign.arrived; }, "both errors");
  ASSERT_TRUE(typed.error);
  EXPECT_EQ(typed.error->cls(), ErrorClass::bad_data);
  EXPECT_EQ(typed.error->info().message, "too few patches");
  ASSERT_TRUE(foreign.error);
  EXPECT_EQ(foreign.error->cls(), ErrorClass::internal);
  EXPECT_NE(std::string(foreign.error->what()).find("Eigen gave up"), std::string::npos);
}

TEST(WorkerPool, RunAsACoroutineReturnsTheResultOrRethrows) {
  asio::io_context io;
  WorkerPool pool(io.get_executor(), WorkerPoolOptions{1, 4, {}});
  auto ok = asio::co_spawn(io, pool.run("a fit", [] { return json("fitted"); }), asio::use_future);
  auto bad = asio::co_spawn(
      io, pool.run("a fit", []() -> json { throw Error(ErrorClass::bad_parameter, "unknown prior"); }), asio::use_future);
  run_until(
      io, [&] {
        return ok.wait_for(std::chrono::seconds(0)) == std::future_status::ready &&
               bad.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
      },
      "both coroutines");
  EXPECT_EQ(ok.get(), json("fitted"));
  try {
    bad.get();
    FAIL() << "the job's error was not rethrown";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_parameter);
  }
}

TEST(WorkerPool, ShutdownCancelsWhatWaitsAndLetsTheRunningJobFinish) {
  asio::io_context io;
  auto pool = std::make_unique<WorkerPool>(io.get_executor(), WorkerPoolOptions{1, 4, {}});
  std::promise<void> release;
  std::promise<void> started;
  auto gate = release.get_future().share();
  Outcome running, waiting;
  pool->submit(
      "the running fit", [&, gate] {
        started.set_value();
        gate.wait();
        return json("finished");
      },
      into(running));
  ASSERT_EQ(started.get_future().wait_for(std::chrono::seconds(60)), std::future_status::ready) << "the worker never started";
  pool->submit(
      "the waiting fit", [] { return json("never"); }, into(waiting));
  // shutdown() joins the worker, so it runs beside the test, which releases the job once the
  // waiting one has been cancelled.
  std::thread stopper([&] { pool->shutdown(); });
  run_until(
      io, [&] { return waiting.arrived; }, "the waiting job's cancellation");
  ASSERT_TRUE(waiting.error);
  EXPECT_EQ(waiting.error->cls(), ErrorClass::aborted);
  EXPECT_THROW(pool->submit(
                   "a late fit", [] { return json(0); }, [](std::exception_ptr, json) {}),
               Error);
  release.set_value();
  stopper.join();
  run_until(
      io, [&] { return running.arrived; }, "the running job's result");
  EXPECT_EQ(running.result, json("finished"));
  pool.reset();  // a second shutdown (the destructor's) is harmless
}

}  // namespace
}  // namespace colorlab::daemon
