#pragma once
// Plain request/response values, so routing and handlers compile without Beast.
#include <functional>
#include <map>
#include <optional>
#include <string>

#include <nlohmann/json_fwd.hpp>

namespace colorlab::http {

struct HttpRequest {
  std::string method;   // "GET"
  std::string target;   // "/v1/runs?limit=5"
  std::string path;     // "/v1/runs"
  std::map<std::string, std::string> query;
  std::map<std::string, std::string> headers;  // lower-case names
  std::string body;

  std::optional<std::string> header(const std::string& lower_name) const;
  // Splits `target` into path and decoded query parameters; false when the target is malformed.
  bool parse_target();
};

struct HttpResponse {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::map<std::string, std::string> headers;

  static HttpResponse json(int status, const nlohmann::json& body);
  static HttpResponse problem(int status, const std::string& code, const std::string& title, const std::string& detail,
                              const std::string& hint = {});
};

using Handler = std::function<HttpResponse(const HttpRequest&)>;

}  // namespace colorlab::http
