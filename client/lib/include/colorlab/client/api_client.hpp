#pragma once
// Talks to colorlabd. A non-2xx answer becomes ApiError carrying the server's problem+json, so
// callers (the CLI, tests) see the server's own detail and hint.
#include <chrono>
#include <map>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/protocol/problem.hpp"

namespace colorlab::client {

struct Endpoint {
  std::string host = "127.0.0.1";
  unsigned short port = 8765;
  std::string unix_socket;  // when set, used instead of host:port

  // "http://HOST:PORT" → Endpoint; throws Error{bad_parameter}.
  static Endpoint from_url(const std::string& url);
  std::string describe() const;
};

class ApiError : public std::runtime_error {
 public:
  explicit ApiError(protocol::Problem p);
  const protocol::Problem& problem() const { return problem_; }

 private:
  protocol::Problem problem_;
};

struct RawResponse {
  int status = 0;
  std::string content_type;
  std::string body;
  std::map<std::string, std::string> headers;
};

class ApiClient {
 public:
  explicit ApiClient(Endpoint endpoint, std::chrono::milliseconds timeout = std::chrono::seconds(30));

  // Any request; throws Error{no_comms} when the daemon is unreachable.
  RawResponse request(const std::string& method, const std::string& target, const std::string& body = {},
                      const std::map<std::string, std::string>& headers = {}) const;
  // JSON request expecting 2xx JSON; throws ApiError with the server's problem otherwise.
  nlohmann::json get(const std::string& target) const;
  nlohmann::json post(const std::string& target, const nlohmann::json& body,
                      const std::map<std::string, std::string>& headers = {}) const;
  nlohmann::json del(const std::string& target) const;  // DELETE

  const Endpoint& endpoint() const { return endpoint_; }

 private:
  nlohmann::json expect_json(const RawResponse& r) const;
  Endpoint endpoint_;
  std::chrono::milliseconds timeout_;
};

}  // namespace colorlab::client
