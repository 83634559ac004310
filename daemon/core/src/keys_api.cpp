// API keys over the API: GET and POST /v1/keys, GET and DELETE /v1/keys/{id} (all admin, checked
// before this runs). The secret is in the POST's answer and nowhere else, ever.
#include "colorlab/core/error.hpp"
#include "colorlab/daemon/access.hpp"
#include "colorlab/daemon/access_api.hpp"
#include "colorlab/protocol/api.hpp"
#include "colorlab/store/api_keys.hpp"
#include "access_body.hpp"

namespace colorlab::daemon {

using http::HttpRequest;
using http::HttpResponse;
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

HttpResponse post_key(ApiContext& ctx, const HttpRequest& req) {
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

std::optional<HttpResponse> handle_keys_api(ApiContext& ctx, const HttpRequest& req) {
  const std::string base = std::string(protocol::kPrefix) + "/keys";
  const std::string& p = req.path;
  if (p != base && p.rfind(base + "/", 0) != 0) return std::nullopt;
  store::ApiKeyStore keys(ctx.store);
  if (p == base || p == base + "/") {
    if (req.method == "GET") {
      json items = json::array();
      for (const auto& k : keys.list()) items.push_back(k.to_json());
      return HttpResponse::json(200, {{"items", items}});
    }
    if (req.method == "POST") return post_key(ctx, req);
    return access_method_not_allowed(req, "GET, POST");
  }
  std::string id = p.substr(base.size() + 1);
  if (id.empty() || id.find('/') != std::string::npos) return std::nullopt;
  if (req.method == "GET") {
    auto key = keys.find(id);
    if (!key) throw Error(ErrorClass::not_found, "no API key with id '" + id + "'", "colorlab keys list shows the ids");
    return key_response(200, *key);
  }
  if (req.method == "DELETE") {
    auto key = keys.revoke(id);
    if (ctx.access) ctx.access->reload();
    return key_response(200, key);
  }
  return access_method_not_allowed(req, "GET, DELETE");
}

}  // namespace colorlab::daemon
