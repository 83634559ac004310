// The v1 API's routes, one row each: method, path pattern, scope, where the handler runs, handler.
// docs/API.md lists the same routes (tests/daemon/route_table_test.cpp checks the two agree).
#include "colorlab/api/route_table.hpp"

#include <array>

#include "routes/handlers.hpp"

namespace colorlab::daemon {

namespace {

using enum Scope;
using enum Placement;
namespace r = routes;

// Pool rows read stored data only (through ctx.reads()); main rows touch live state or the writer.
// Kept as laid out by hand (clang-format would undo the columns): one aligned row per route.
// clang-format off
constexpr Route kRoutes[] = {
    // method   pattern                                scope    runs on  handler
    {"GET",    "/v1",                                  read,    main,    r::get_root},
    {"GET",    "/v1/instruments",                      read,    main,    r::get_instruments},
    {"GET",    "/v1/ports",                            read,    main,    r::get_ports},
    {"GET",    "/v1/campaigns",                        read,    main,    r::get_campaigns},
    {"GET",    "/v1/lab/cabinet",                      read,    main,    r::get_lab_cabinet},
    {"GET",    "/v1/lab/lenses",                       read,    main,    r::get_lab_lenses},
    {"GET",    "/v1/events",                           read,    pool,    r::get_events},
    {"GET",    "/v1/events/stream",                    read,    main,    r::get_event_stream},
    {"POST",   "/v1/executions",                       control, main,    r::post_execution},
    {"GET",    "/v1/executions",                       read,    pool,    r::get_executions},
    {"GET",    "/v1/executions/{id}",                  read,    main,    r::get_execution},
    {"POST",   "/v1/executions/{id}/pause",            control, main,    r::post_execution_pause},
    {"POST",   "/v1/executions/{id}/resume",           control, main,    r::post_execution_resume},
    {"POST",   "/v1/executions/{id}/abort",            control, main,    r::post_execution_abort},
    {"GET",    "/v1/requests",                         read,    main,    r::get_requests},
    {"GET",    "/v1/requests/{id}",                    read,    main,    r::get_request},
    {"POST",   "/v1/requests/{id}",                    control, main,    r::post_request_answer},
    {"GET",    "/v1/queue",                            read,    main,    r::get_queue},
    {"POST",   "/v1/queue",                            control, main,    r::post_queue},
    {"POST",   "/v1/queue/start",                      control, main,    r::post_queue_start},
    {"POST",   "/v1/queue/stop",                       control, main,    r::post_queue_stop},
    {"GET",    "/v1/queue/groups/{id}",                read,    main,    r::get_queue_group},
    {"GET",    "/v1/queue/groups/{id}/report",         read,    main,    r::get_queue_group_report},
    {"GET",    "/v1/queue/{id}",                       read,    main,    r::get_queue_item},
    {"DELETE", "/v1/queue/{id}",                       control, main,    r::delete_queue_item},
    {"POST",   "/v1/queue/{id}/move",                  control, main,    r::post_queue_move},
    {"GET",    "/v1/keys",                             admin,   main,    r::get_keys},
    {"POST",   "/v1/keys",                             admin,   main,    r::post_key},
    {"GET",    "/v1/keys/{id}",                        admin,   main,    r::get_key},
    {"DELETE", "/v1/keys/{id}",                        admin,   main,    r::delete_key},
    {"GET",    "/v1/control",                          read,    main,    r::get_control},
    {"POST",   "/v1/control/acquire",                  control, main,    r::post_control_acquire, true},
    {"POST",   "/v1/control/release",                  control, main,    r::post_control_release, true},
    {"GET",    "/v1/runs",                             read,    pool,    r::get_runs},
    {"GET",    "/v1/runs/{id}",                        read,    pool,    r::get_run},
    {"GET",    "/v1/runs/{id}/script",                 read,    pool,    r::get_run_script},
    {"GET",    "/v1/runs/{id}/measurements",           read,    pool,    r::get_run_measurements},
    {"GET",    "/v1/runs/{id}/export",                 read,    pool,    r::get_run_export},
    {"GET",    "/v1/runs/{id}/report",                 read,    pool,    r::get_run_report},
    {"GET",    "/v1/runs/{id}/blobs",                  read,    pool,    r::get_run_blobs},
    // A verification compared where the rendering is, stored as a `verify` run: a write, like starting a campaign.
    {"POST",   "/v1/verifications",                    control, main,    r::post_verification},
    {"GET",    "/v1/blobs/{sha256}",                   read,    pool,    r::get_blob},
    {"GET",    "/v1/blobs/{sha256}/preview.png",       read,    pool,    r::get_blob_preview},
    // Stores nothing: the read scope; the locating is the pool's work, not the main thread's.
    {"POST",   "/v1/blobs/{sha256}/locate-chart",      read,    pool,    r::post_locate_chart},
    {"GET",    "/v1/blobs/check",                      read,    pool,    r::get_blob_check},
    // Retention deletes kept frames' files: not something a campaign operator's key should do.
    {"POST",   "/v1/blobs/retention",                  admin,   main,    r::post_blob_retention},
    // The bench's own files only (the event log, the agent's notes): never the network.
    {"GET",    "/v1/shipping",                         read,    pool,    r::get_shipping},
};
// clang-format on

}  // namespace

std::span<const Route> route_table() { return kRoutes; }

}  // namespace colorlab::daemon
