#include "colorlab/daemon/simulator_hands.hpp"

#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/streambuf.hpp>
#include <boost/asio/use_awaitable.hpp>
#include <boost/asio/write.hpp>

#include "colorlab/core/error.hpp"

namespace colorlab::daemon {

namespace asio = boost::asio;
using nlohmann::json;

SimulatorHands::SimulatorHands(asio::any_io_executor executor, std::filesystem::path control_socket)
    : executor_(std::move(executor)), socket_(std::move(control_socket)) {}

asio::awaitable<json> SimulatorHands::command(json cmd) {
  asio::local::stream_protocol::socket s(executor_);
  // The deadline closes the socket, which ends whichever operation is pending with an error.
  auto timed_out = std::make_shared<bool>(false);
  asio::steady_timer deadline(executor_, std::chrono::seconds(5));
  deadline.async_wait([&s, timed_out](boost::system::error_code ec) {
    if (ec) return;
    *timed_out = true;
    boost::system::error_code ignored;
    s.close(ignored);
  });
  json answer;
  try {
    co_await s.async_connect(asio::local::stream_protocol::endpoint(socket_.string()), asio::use_awaitable);
    std::string line = cmd.dump() + "\n";
    co_await asio::async_write(s, asio::buffer(line), asio::use_awaitable);
    asio::streambuf buf(1 << 20);
    std::size_t n = co_await asio::async_read_until(s, buf, '\n', asio::use_awaitable);
    std::string reply(asio::buffers_begin(buf.data()), asio::buffers_begin(buf.data()) + static_cast<long>(n));
    answer = json::parse(reply, nullptr, false);
  } catch (const boost::system::system_error& e) {
    deadline.cancel();
    if (*timed_out) throw Error(ErrorClass::timeout, "the simulated lab's control channel did not answer within 5 s");
    throw Error(ErrorClass::no_comms, "the simulated lab's control channel " + socket_.string() + ": " + e.code().message());
  }
  deadline.cancel();
  if (answer.is_discarded() || !answer.is_object()) throw Error(ErrorClass::protocol_error, "the simulated lab answered something that is not JSON");
  if (!answer.value("ok", false)) {
    throw Error(ErrorClass::device_error, "the simulated lab refused " + cmd.value("cmd", std::string()) + ": " +
                                              answer.value("message", std::string("no reason given")));
  }
  co_return answer;
}

asio::awaitable<std::optional<json>> SimulatorHands::perform(const std::string& action, const json& details) {
  if (action == "aim_meter") {
    if (!details.contains("row") || !details.contains("col") || !details["row"].is_number_integer() ||
        !details["col"].is_number_integer()) {
      throw Error(ErrorClass::script_error, "aim_meter needs details = {row = R, col = C} (integers) on the simulated lab");
    }
    json cmd{{"cmd", "aim"}, {"row", details["row"]}, {"col", details["col"]}};
    co_await command(cmd);
    co_return json{{"aimed", {details["row"], details["col"]}}};
  }
  if (action == "load_chart") {
    // The simulated SpectroScan always has its chart in place; the camera sees the cabinet's chart.
    json cmd{{"cmd", "announce"}};
    co_await command(cmd);
    co_return json{{"chart", "in place"}};
  }
  if (action == "aim_camera") {
    // floor-luminance: the chart out of the cabinet and the cameras at the whole floor ("floor"), or back ("chart").
    const std::string view = details.is_object() ? details.value("view", std::string()) : std::string();
    if (view != "floor" && view != "chart") {
      throw Error(ErrorClass::script_error, "aim_camera needs details = {view = \"floor\" | \"chart\"} on the simulated lab");
    }
    json cmd{{"cmd", "camera_view"}, {"view", view}};
    co_await command(cmd);
    co_return json{{"camera_view", view}};
  }
  if (action == "place_chart") {
    // lens-calibration: the chart at the pose the details describe (in the simulator's own terms: rotation_deg, tilt_deg,
    // swing_deg, fill, shift_x, shift_y), or back at its measuring place (pose = "measurement"). The pose's number and
    // the chart's name are for the record, not the simulator.
    if (!details.is_object()) throw Error(ErrorClass::script_error, "place_chart needs details = {pose = k, tilt_deg = …} on the simulated lab");
    json placement = json::object();
    if (details.value("pose", json()) == "measurement") {
      placement = "configured";
    } else {
      for (const char* key : {"rotation_deg", "tilt_deg", "swing_deg", "fill", "shift_x", "shift_y"})
        if (details.contains(key)) placement[key] = details[key];
      if (placement.empty())
        throw Error(ErrorClass::script_error,
                    "place_chart on the simulated lab needs the pose in numbers (details = {fill, tilt_deg, swing_deg, rotation_deg, "
                    "shift_x, shift_y}) or details = {pose = \"measurement\"}");
    }
    json cmd{{"cmd", "place_chart"}, {"placement", placement}};
    co_await command(cmd);
    co_return json{{"chart_placed", placement}};
  }
  if (action == "white_tile") {
    json cmd{{"cmd", "place"}, {"target", "white_tile"}};
    co_await command(cmd);
    co_return json{{"head", "on the white tile"}};
  }
  co_return std::nullopt;
}

asio::awaitable<std::optional<json>> SimulatorHands::put_back(const std::string& action, const json& details) {
  // As perform read them: a pose of "measurement" is the chart's measuring place; a view is a string.
  const bool object = details.is_object();
  const std::string pose = object && details.contains("pose") ? details["pose"].dump() : std::string();
  const std::string view = object && details.contains("view") && details["view"].is_string() ? details["view"].get<std::string>() : std::string();
  if (action == "place_chart" && pose != "\"measurement\"") {
    json cmd{{"cmd", "place_chart"}, {"placement", "configured"}};
    co_await command(cmd);
    co_return json{{"chart_placed", "configured"}};
  }
  if (action == "aim_camera" && view == "floor") {
    json cmd{{"cmd", "camera_view"}, {"view", "chart"}};
    co_await command(cmd);
    co_return json{{"camera_view", "chart"}};
  }
  co_return std::nullopt;
}

}  // namespace colorlab::daemon
