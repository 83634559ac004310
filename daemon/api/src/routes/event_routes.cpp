// GET /v1/events: the event log, paged. GET /v1/events/stream: the event log as Server-Sent Events (docs/API.md "Live events").
// A fresh stream starts with a snapshot of the lab's state taken on the main thread, where that
// state lives, stamped with the newest event seq at that moment; then every later event in seq
// order. A stream resumed with Last-Event-ID (or ?after=) gets exactly the events after it: they
// come from the event log on disk, so a restart of the daemon between loses none and repeats none.
// Each stream holds at most one page of events; a client that does not take a chunk within the
// server's write deadline is dropped and resumes with Last-Event-ID.
#include <boost/asio/this_coro.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/daemon/event_hub.hpp"
#include "colorlab/daemon/night_queue.hpp"
#include "colorlab/daemon/read_connections.hpp"
#include "colorlab/protocol/api.hpp"
#include "handlers.hpp"
#include "query.hpp"

namespace colorlab::daemon::routes {

using nlohmann::json;

namespace {

constexpr unsigned kPage = 256;
constexpr std::chrono::milliseconds kKeepAlive{15000};

std::string sse(std::int64_t id, const std::string& event, const std::string& data) {
  return "id: " + std::to_string(id) + "\nevent: " + event + "\ndata: " + data + "\n\n";
}

std::int64_t resume_point(const HttpRequest& req, bool& resumed) {
  std::optional<std::string> text = req.header("last-event-id");
  if (!text) {
    if (auto it = req.query.find("after"); it != req.query.end()) text = it->second;
  }
  resumed = text.has_value();
  if (!text) return 0;
  try {
    std::size_t used = 0;
    long long v = std::stoll(*text, &used);
    if (used != text->size() || v < 0) throw std::invalid_argument("id");
    return v;
  } catch (const std::exception&) {
    throw Error(ErrorClass::bad_parameter, "Last-Event-ID (or after) must be a non-negative event sequence number",
                "send back the id: of the last event received");
  }
}

json snapshot(ApiContext& ctx, std::int64_t last_seq) {
  json executions = json::array();
  for (const auto& e : ctx.store.unfinished_executions()) {
    json j = e.to_json();
    if (auto why = ctx.executions.live_suspension(e.id)) {
      j["status"] = "suspended";
      j["reason"] = *why;
    }
    executions.push_back(j);
  }
  json instruments = ctx.instruments.describe_all();
  json requests = json::array();
  if (ctx.desk) {
    for (const auto& r : ctx.desk->pending()) requests.push_back(r.to_json());
  }
  json j{{"last_seq", last_seq}, {"executions", executions}, {"instruments", instruments}, {"requests", requests}};
  if (ctx.queue) j["queue"] = ctx.queue->describe(10);
  return j;
}

}  // namespace

HttpResponse get_events(ApiContext& ctx, const HttpRequest& req, const PathParams&) {
  const std::int64_t after = non_negative_query(req, "after", "after must be a non-negative event sequence number");
  std::optional<std::string> topic;
  if (auto it = req.query.find("topic"); it != req.query.end()) topic = it->second;
  auto events = ctx.reads().events(after, page_limit(req), topic);
  json items = json::array();
  for (const auto& e : events) items.push_back({{"seq", e.seq}, {"time", e.time}, {"topic", e.topic}, {"payload", e.payload}});
  std::int64_t last = events.empty() ? after : events.back().seq;
  return HttpResponse::json(200, {{"items", items}, {"last_seq", last}});
}

HttpResponse get_event_stream(ApiContext& ctx, const HttpRequest& req, const PathParams&) {
  if (!ctx.events || !ctx.readers) throw Error(ErrorClass::unsupported, "this daemon serves no live event stream");
  bool resumed = false;
  std::int64_t after = resume_point(req, resumed);
  std::optional<std::string> topic;
  if (auto it = req.query.find("topic"); it != req.query.end()) topic = it->second;

  std::string first;
  if (!resumed) {
    // The writer's view, on the main thread, read in one snapshot of the database: steps committed
    // meanwhile on the committer's thread (step_committer.hpp) come after `after`, as events.
    json state;
    {
      const auto one_view = ctx.store.read_snapshot();
      after = ctx.store.last_event_seq();
      state = snapshot(ctx, after);
    }
    first = sse(after, "snapshot", state.dump());
  }
  HttpResponse r;
  r.content_type = "text/event-stream";
  r.headers["Cache-Control"] = "no-cache";
  r.headers["X-Accel-Buffering"] = "no";  // a proxy in front must not hold events back
  ReadConnections* readers = ctx.readers;
  EventHub* hub = ctx.events;
  r.stream = [readers, hub, after, topic, first](http::StreamWriter& out) -> boost::asio::awaitable<void> {
    if (!co_await out.send("retry: 2000\n\n" + first)) co_return;
    std::int64_t last = after;
    for (;;) {
      // The whole log, filtered here, so `last` passes events of other topics too.
      auto events = readers->for_this_thread().events(last, kPage, std::nullopt);
      std::string chunk;
      for (const auto& e : events) {
        last = e.seq;
        if (topic && e.topic != *topic) continue;
        chunk += sse(e.seq, e.topic, json{{"seq", e.seq}, {"time", e.time}, {"topic", e.topic}, {"payload", e.payload}}.dump());
      }
      if (!chunk.empty() && !co_await out.send(chunk)) co_return;
      if (events.size() == kPage) continue;  // still catching up
      if (hub->stopped()) co_return;
      if (!co_await hub->wait_beyond(last, kKeepAlive)) {
        if (!co_await out.send(": keep-alive\n\n")) co_return;
      }
    }
  };
  return r;
}

}  // namespace colorlab::daemon::routes
