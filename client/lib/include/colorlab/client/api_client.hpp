#pragma once
#include <functional>
#include <string_view>
// Talks to colorlabd over a Unix socket, HTTP or HTTPS (the server's certificate verified against
// a CA file or the system's store, and its name or address checked). A non-2xx answer becomes
// ApiError carrying the server's problem+json, so callers (the CLI, tests) see the server's own
// detail and hint. With an API key, every request carries "Authorization: Bearer <key>".
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
  bool tls = false;         // https://
  std::string ca_file;      // PEM certificates the server's is verified against; empty: the system's store

  // "http://HOST:PORT" or "https://HOST:PORT" (an IPv6 address in brackets) → Endpoint; throws
  // Error{bad_parameter}.
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
  // Sends the key with every request (empty: none).
  ApiClient& with_api_key(std::string key) {
    api_key_ = std::move(key);
    return *this;
  }

  // Any request; throws Error{no_comms} when the daemon is unreachable.
  RawResponse request(const std::string& method, const std::string& target, const std::string& body = {},
                      const std::map<std::string, std::string>& headers = {}) const;
  // JSON request expecting 2xx JSON; throws ApiError with the server's problem otherwise.
  nlohmann::json get(const std::string& target) const;
  nlohmann::json post(const std::string& target, const nlohmann::json& body,
                      const std::map<std::string, std::string>& headers = {}) const;
  nlohmann::json del(const std::string& target) const;  // DELETE
  // GET with a body read as it arrives (GET /v1/events/stream): `on_data` gets each piece until it returns
  // false or the daemon ends the body. Throws ApiError for a refusal, Error{no_comms} for a lost link.
  void stream(const std::string& target, const std::function<bool(std::string_view)>& on_data,
              const std::map<std::string, std::string>& headers = {}) const;

  const Endpoint& endpoint() const { return endpoint_; }

 private:
  nlohmann::json expect_json(const RawResponse& r) const;
  Endpoint endpoint_;
  std::chrono::milliseconds timeout_;
  std::string api_key_;
};

}  // namespace colorlab::client
