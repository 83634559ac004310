#pragma once
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
};

http::HttpResponse handle_api(ApiContext& ctx, const http::HttpRequest& req);
// /v1/requests (operator requests); nullopt when the path is not theirs. Throws colorlab::Error.
std::optional<http::HttpResponse> handle_operator_api(ApiContext& ctx, const http::HttpRequest& req);

}  // namespace colorlab::daemon
