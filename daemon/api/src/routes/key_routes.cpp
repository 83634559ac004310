// API keys over the API: GET and POST /v1/keys, GET and DELETE /v1/keys/{id} (all admin, checked
// before this runs). The secret is in the POST's answer and nowhere else, ever.
#include "colorlab/core/error.hpp"
#include "colorlab/api/access.hpp"
#include "colorlab/protocol/api.hpp"
#include "colorlab/store/api_keys.hpp"
#include "access_body.hpp"
#include "handlers.hpp"

namespace colorlab::daemon::routes {

using nlohmann::json;

namespace {

constexpr const char* kExample = R"({"name": "alice-laptop", "scope": "read"})";

HttpResponse key_response(int status, const store::ApiKeyRecord& key, json extra = json::object()) {
  json j = key.to_json();
  j.update(extra);
  auto r = HttpResponse::json(status, j);
  r.headers["Location"] = std::string(protocol::kPrefix) + "/keys/" + key.id;
  return r;
}

HttpResponse create_key(ApiContext& ctx, const HttpRequest& req) {
  json body = access_body(req, kExample);
  if (!body.contains("name") || !body["name"].is_string()) {
    throw Error(ErrorClass::bad_parameter, "the body needs a string 'name'", std::string("e.g. ") + kExample);
  }
  std::string scope = "read";
  if (body.contains("scope")) {
    if (!body["scope"].is_string()) throw Error(ErrorClass::bad_parameter, "'scope' must be read, control or admin");
    scope = body["scope"].get<std::string>();
  }
  auto created = store::ApiKeyStore(ctx.store).create(body["name"].get<std::string>(), scope);
  if (ctx.access) ctx.access->reload();
  auto r = key_response(201, created.key, {{"secret", created.secret}});
  // The one answer that holds the secret must not linger in a cache.
  r.headers["Cache-Control"] = "no-store";
  return r;
}

}  // namespace

HttpResponse get_keys(ApiContext& ctx, const HttpRequest&, const PathParams&) {
  json items = json::array();
  for (const auto& k : store::ApiKeyStore(ctx.store).list()) items.push_back(k.to_json());
  return HttpResponse::json(200, {{"items", items}});
}

HttpResponse post_key(ApiContext& ctx, const HttpRequest& req, const PathParams&) { return create_key(ctx, req); }

HttpResponse get_key(ApiContext& ctx, const HttpRequest&, const PathParams& params) {
  const std::string& id = params["id"];
  auto key = store::ApiKeyStore(ctx.store).find(id);
  if (!key) throw Error(ErrorClass::not_found, "no API key with id '" + id + "'", "colorlab keys list shows the ids");
  return key_response(200, *key);
}

HttpResponse delete_key(ApiContext& ctx, const HttpRequest&, const PathParams& params) {
  auto key = store::ApiKeyStore(ctx.store).revoke(params["id"]);
  if (ctx.access) ctx.access->reload();
  return key_response(200, key);
}

}  // namespace colorlab::daemon::routes
