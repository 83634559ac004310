#include "colorlab/api/problem.hpp"

#include "colorlab/protocol/api.hpp"
#include "colorlab/protocol/problem.hpp"
#include "colorlab/daemon/executions.hpp"
#include "colorlab/daemon/worker_pool.hpp"
#include "colorlab/store/queue.hpp"

namespace colorlab::daemon {

namespace {

http::HttpResponse respond(const protocol::Problem& p, const nlohmann::json& extra) {
  nlohmann::json body = p.to_json();
  if (!extra.empty()) body.update(extra);
  http::HttpResponse r;
  r.status = p.status;
  r.content_type = std::string(protocol::kContentProblem);
  // A detail may quote the client's bytes (a path that is not UTF-8): replaced, never a throw.
  r.body = body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return r;
}

}  // namespace

http::HttpResponse problem_response(int status, const std::string& code, const std::string& title,
                                    const std::string& detail, const std::string& hint, const nlohmann::json& extra) {
  return respond(protocol::problem_for_status(status, code, title, detail, hint), extra);
}

http::HttpResponse error_response(const Error& e, const std::string& instance) {
  auto p = protocol::problem_from_error(e);
  // A refusal about a queue item's references: its own code, so a client can tell it from another conflict.
  if (const auto* q = dynamic_cast<const store::QueueConflict*>(&e)) p.code = q->code();
  p.instance = instance;
  // The worker pool's queue is full: busy, not broken; the client may try again shortly.
  if (const auto* full = dynamic_cast<const WorkerPoolFull*>(&e)) {
    p.code = "busy";
    p.title = "Busy";
    auto r = respond(p, nlohmann::json::object());
    r.headers["Retry-After"] = std::to_string(full->retry_after_s());
    return r;
  }
  // Another execution holds the lab: named, so a client can follow or abort it.
  if (const auto* busy = dynamic_cast<const LabBusy*>(&e)) {
    p.code = "lab-busy";
    return respond(p, {{"execution_id", busy->execution_id()}});
  }
  return respond(p, nlohmann::json::object());
}

}  // namespace colorlab::daemon
