#pragma once
// The v1 HTTP API (docs/API.md): routes requests to the store, the instruments and the
// executions. Every error leaves as RFC 9457 problem+json.
#include <string>

#include "colorlab/campaigns/catalogue.hpp"
#include "colorlab/daemon/executions.hpp"
#include "colorlab/drivers/discovery.hpp"
#include "colorlab/http/message.hpp"
#include "colorlab/store/store.hpp"

namespace colorlab::daemon {

struct ApiContext {
  store::Store& store;
  const campaigns::InstrumentSet& instruments;
  campaigns::ScriptCatalogue& catalogue;
  Executions& executions;
  bool simulated_lab = false;
  std::string started_at;
  const drivers::Discovery* discovery = nullptr;
  std::string hotplug_status;
};

http::HttpResponse handle_api(ApiContext& ctx, const http::HttpRequest& req);

}  // namespace colorlab::daemon
