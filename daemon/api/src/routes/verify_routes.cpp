// POST /v1/verifications: a rendering's verification, compared where the rendering is (colorlab verify, the Python
// client), stored here as a finished `verify` run (docs/verify.md "Using it"). Reading it back is GET /v1/runs/{id}.
#include "colorlab/core/error.hpp"
#include "colorlab/protocol/api.hpp"
#include "colorlab/verify/compare/stored_request.hpp"
#include "access_body.hpp"
#include "handlers.hpp"
#include "store_verification.hpp"

namespace colorlab::daemon::routes {

using nlohmann::json;

namespace {

constexpr const char* kExample =
    R"({"rendering": "box.exr", "against": ["<run id>"], "scale": 1, "k": 2, "result": {"comparisons": [...]}})";

}  // namespace

HttpResponse post_verification(ApiContext& ctx, const HttpRequest& req, const PathParams&) {
  const json body = access_body(req, kExample);
  const auto stored = verify::stored_from_request(body);
  // A verification names the runs it was checked against: they must be this daemon's, or it could not be read back.
  for (const auto& id : stored.params["against"]) {
    if (!ctx.store.run(id.get<std::string>()))
      throw Error(ErrorClass::not_found, "no run '" + id.get<std::string>() + "' to have verified against",
                  "colorlab runs lists this daemon's runs");
  }
  const std::string run_id = verify::store_verification(ctx.store, stored);
  auto r = HttpResponse::json(201, {
                                       {"run_id", run_id},
                                       {"verdict", stored.summary["verdict"]},
                                       {"comparisons", stored.measurements.size()},
                                   });
  r.headers["Location"] = std::string(protocol::kPrefix) + "/runs/" + run_id;
  return r;
}

}  // namespace colorlab::daemon::routes
