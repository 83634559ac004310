// The daemon and the lab as they are now: GET /v1, /v1/instruments, /v1/ports, /v1/campaigns, /v1/lab/cabinet, /v1/lab/lenses.
#include <nlohmann/json.hpp>

#include "colorlab/daemon/executions.hpp"
#include "colorlab/protocol/api.hpp"
#include "handlers.hpp"

#ifndef COLORLAB_VERSION
#define COLORLAB_VERSION "dev"
#endif

namespace colorlab::daemon::routes {

using nlohmann::json;

namespace {

json discovered_json(const drivers::DiscoveredInstrument& d) {
  json j{{"id", d.id}, {"kind", d.kind}, {"port", d.port}, {"from_config", d.from_rule}};
  if (!d.stable_port.empty()) j["stable_port"] = d.stable_port;
  if (d.usb_vid) j["usb_vid"] = *d.usb_vid;
  if (d.usb_pid) j["usb_pid"] = *d.usb_pid;
  if (!d.usb_serial.empty()) j["usb_serial"] = d.usb_serial;
  if (!d.product.empty()) j["product"] = d.product;
  return j;
}

}  // namespace

HttpResponse get_root(ApiContext& ctx, const HttpRequest&, const PathParams&) {
  json features = json::array({"instruments", "ports", "events", "campaigns", "lua-campaigns", "executions",
                               "execution-control", "resume-after-restart", "runs", "run-script", "problem+json",
                               "cursor-paging", "idempotency-key", "operator-requests", "queue", "measurement-pages",
                               "event-stream", "blobs", "locate-chart", "exports", "api-keys", "control-lock", "tls", "shipping"});
  return HttpResponse::json(200, {{"server", "colorlabd"},
                                  {"server_version", COLORLAB_VERSION},
                                  {"api_version", protocol::kApiVersion},
                                  {"started_at", ctx.started_at},
                                  {"simulated_lab", ctx.simulated_lab},
                                  {"running_executions", ctx.executions.running()},
                                  {"features", features},
                                  {"limits", {
                                                 {"max_request_body", protocol::kMaxRequestBody},
                                                 {"max_page_limit", protocol::kMaxPageLimit},
                                             }}});
}

HttpResponse get_instruments(ApiContext& ctx, const HttpRequest&, const PathParams&) {
  return HttpResponse::json(200, {{"items", ctx.instruments.describe_all()}});
}

HttpResponse get_campaigns(ApiContext& ctx, const HttpRequest&, const PathParams&) {
  // Re-read on every request: a script dropped into the campaigns directory appears at once.
  ctx.catalogue.refresh();
  json items = json::array();
  for (const auto& c : ctx.catalogue.all()) items.push_back(c->to_json());
  for (const auto& s : ctx.catalogue.sequences()) items.push_back(s->to_json());  // kind "sequence"
  json broken = json::array();
  for (const auto& b : ctx.catalogue.broken()) broken.push_back({{"path", b.path.string()}, {"error", b.error}});
  json dirs = json::array();
  for (const auto& d : ctx.catalogue.directories()) dirs.push_back({{"path", d.path.string()}, {"origin", d.origin}});
  return HttpResponse::json(200, {{"items", items}, {"broken", broken}, {"directories", dirs}});
}

HttpResponse get_ports(ApiContext& ctx, const HttpRequest&, const PathParams&) {
  json items = json::array();
  if (ctx.discovery) {
    for (const auto& d : ctx.discovery->present()) items.push_back(discovered_json(d));
  }
  return HttpResponse::json(200, {{"items", items}, {"hotplug", ctx.hotplug_status}});
}

// The cabinet's geometry from colorlabd's configuration (validated at start), for `colorlab scene`.
HttpResponse get_lab_cabinet(ApiContext& ctx, const HttpRequest&, const PathParams&) {
  return HttpResponse::json(200, ctx.cabinet);
}

// The lab's lens calibrations from colorlabd's configuration (validated at start), for `colorlab scene` and `colorlab lens`.
HttpResponse get_lab_lenses(ApiContext& ctx, const HttpRequest&, const PathParams&) {
  return HttpResponse::json(200, ctx.lenses.is_null() ? nlohmann::json{{"items", nlohmann::json::array()}} : ctx.lenses);
}

}  // namespace colorlab::daemon::routes
