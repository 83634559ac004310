#pragma once
// Asio completion-token adapters, so the daemon can `co_await async_capture(cam, n, sink,
// asio::use_awaitable)`. The camera's threads do the work; the completion is posted to the
// handler's associated executor (the daemon's strand), never run on a camera thread, and the
// work guard keeps that executor's io_context alive meanwhile.
#include <boost/asio/associated_executor.hpp>
#include <boost/asio/async_result.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/post.hpp>
#include <memory>
#include <optional>

#include "colorlab/drivers/camera/camera.hpp"

namespace colorlab::drivers::camera {

namespace detail {

// Camera callbacks are std::function (copyable); Asio handlers may be move-only.
template <class Handler, class... Args>
auto post_to_handler(Handler&& handler) {
  auto ex = boost::asio::get_associated_executor(handler);
  auto state = std::make_shared<std::pair<std::decay_t<Handler>, decltype(boost::asio::make_work_guard(ex))>>(
      std::forward<Handler>(handler), boost::asio::make_work_guard(ex));
  return [state](Args... args) {
    auto work = std::move(state->second);
    boost::asio::post(work.get_executor(),
                      [h = std::move(state->first), ... a = std::move(args)]() mutable { std::move(h)(std::move(a)...); });
  };
}

}  // namespace detail

// Completes with the CaptureReport (partial series have report.error set).
template <class Token>
auto async_capture(Camera& camera, std::size_t n_frames, FrameSink sink, Token&& token, CaptureOptions options = {}) {
  return boost::asio::async_initiate<Token, void(CaptureReport)>(
      [&camera, n_frames, options](auto handler, FrameSink s) {
        camera.capture(n_frames, std::move(s),
                       detail::post_to_handler<decltype(handler), CaptureReport>(std::move(handler)), options);
      },
      token, std::move(sink));
}

// Complete with std::optional<Error> (nullopt = success).
template <class Token>
auto async_connect(Camera& camera, Token&& token) {
  return boost::asio::async_initiate<Token, void(std::optional<Error>)>(
      [&camera](auto handler) {
        camera.connect(detail::post_to_handler<decltype(handler), std::optional<Error>>(std::move(handler)));
      },
      token);
}

template <class Token>
auto async_configure(Camera& camera, CameraSettings settings, Token&& token) {
  return boost::asio::async_initiate<Token, void(std::optional<Error>)>(
      [&camera](auto handler, CameraSettings s) {
        camera.configure(std::move(s),
                         detail::post_to_handler<decltype(handler), std::optional<Error>>(std::move(handler)));
      },
      token, std::move(settings));
}

}  // namespace colorlab::drivers::camera
