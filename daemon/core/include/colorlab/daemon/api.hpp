#pragma once
#include <filesystem>
// The v1 HTTP API (docs/API.md): routes requests to the store, the instruments and the
// executions. Every error leaves as RFC 9457 problem+json.
#include <optional>
#include <string>

#include "colorlab/campaigns/catalogue.hpp"
#include "colorlab/campaigns/operator_desk.hpp"
#include "colorlab/daemon/executions.hpp"
#include "colorlab/drivers/discovery.hpp"
#include "colorlab/http/message.hpp"
#include "colorlab/store/store.hpp"

namespace colorlab::daemon {

class NightQueue;
class BlobService;
class ReadConnections;
class EventHub;
class Access;
class ControlLock;

class ReportService;

struct ApiContext {
  store::Store& store;
  const campaigns::InstrumentSet& instruments;
  campaigns::ScriptCatalogue& catalogue;
  Executions& executions;
  bool simulated_lab = false;
  std::string started_at;
  const drivers::Discovery* discovery = nullptr;
  std::string hotplug_status;
  campaigns::OperatorDesk* desk = nullptr;
  NightQueue* queue = nullptr;  // /v1/queue (queue_api.cpp)
  BlobService* blobs = nullptr;  // /v1/blobs, /v1/runs/{id}/blobs (blob_api.cpp)
  // Stored data is served on the HTTP pool's threads, each through its own read-only connection;
  // `store` (the one writer) belongs to the daemon's main thread.
  ReadConnections* readers = nullptr;
  EventHub* events = nullptr;  // wakes live event streams (event_stream_api.cpp)
  store::Store& reads();
  Access* access = nullptr;       // checked first for every request (access.hpp)
  ControlLock* control = nullptr;  // /v1/control (control_api.cpp)
  std::filesystem::path console_dir;
  ReportService* reports = nullptr;  // GET /v1/runs/{id}/report (report_service.hpp)  // the web console's static files, served at / (console_files.cpp)
};

http::HttpResponse handle_api(ApiContext& ctx, const http::HttpRequest& req);
// Whether a request only reads stored data (runs, measurements, blobs, exports, the event log), so
// it may be served on an HTTP pool thread through ctx.reads(); everything else runs on the main thread.
bool serves_stored_data(const http::HttpRequest& req);
// GET /v1/events/stream (or /v1/events with Accept: text/event-stream): Server-Sent Events.
http::HttpResponse get_event_stream(ApiContext& ctx, const http::HttpRequest& req);
bool wants_event_stream(const http::HttpRequest& req);
// /v1/requests (operator requests); nullopt when the path is not theirs. Throws colorlab::Error.
std::optional<http::HttpResponse> handle_operator_api(ApiContext& ctx, const http::HttpRequest& req);

}  // namespace colorlab::daemon
