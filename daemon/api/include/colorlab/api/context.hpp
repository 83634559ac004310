#pragma once
// What the API's handlers reach: the daemon's services, handed over by the composition root
// (daemon/app/daemon.cpp). Its own header so that no route includes the router.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/campaigns/catalogue.hpp"
#include "colorlab/campaigns/operator_desk.hpp"
#include "colorlab/daemon/executions.hpp"
#include "colorlab/drivers/discovery.hpp"
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
  NightQueue* queue = nullptr;   // /v1/queue (queue_routes.cpp)
  BlobService* blobs = nullptr;  // /v1/blobs, /v1/runs/{id}/blobs (blob_routes.cpp)
  // Stored data is served on the HTTP pool's threads, each through its own read-only connection;
  // `store` (the one writer) belongs to the daemon's main thread. Which routes run where: the route table.
  ReadConnections* readers = nullptr;
  EventHub* events = nullptr;  // wakes live event streams (event_routes.cpp)
  store::Store& reads();
  Access* access = nullptr;           // checked for every API request, after the console's files (router.cpp)
  ControlLock* control = nullptr;     // /v1/control (control_routes.cpp)
  std::filesystem::path console_dir;  // the web console's static files, served at / (console_files.cpp)
  ReportService* reports = nullptr;   // GET /v1/runs/{id}/report (report_response.hpp)
  // GET /v1/lab/cabinet: {source: "config" | "default", cabinet: cabinet_to_json(...)} (lab_routes.cpp)
  nlohmann::json cabinet;
  // GET /v1/lab/lenses: {items: [lens_to_json(...)]}, the configuration's [[lens]] calibrations (lab_routes.cpp)
  nlohmann::json lenses;
};

}  // namespace colorlab::daemon
