#include "colorlab/client/api_client.hpp"

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http.hpp>

#include "colorlab/core/error.hpp"

namespace colorlab::client {

namespace asio = boost::asio;
namespace bhttp = boost::beast::http;

Endpoint Endpoint::from_url(const std::string& url) {
  const std::string scheme = "http://";
  if (url.rfind(scheme, 0) != 0) {
    throw Error(ErrorClass::bad_parameter, "URL '" + url + "' must start with http://", "e.g. http://127.0.0.1:8765");
  }
  std::string rest = url.substr(scheme.size());
  if (auto slash = rest.find('/'); slash != std::string::npos) rest = rest.substr(0, slash);
  Endpoint e;
  auto colon = rest.rfind(':');
  if (colon == std::string::npos) {
    e.host = rest;
    e.port = 80;
  } else {
    e.host = rest.substr(0, colon);
    try {
      int p = std::stoi(rest.substr(colon + 1));
      if (p <= 0 || p > 65535) throw std::out_of_range("port");
      e.port = static_cast<unsigned short>(p);
    } catch (const std::exception&) {
      throw Error(ErrorClass::bad_parameter, "URL '" + url + "' has an invalid port");
    }
  }
  if (e.host.empty()) throw Error(ErrorClass::bad_parameter, "URL '" + url + "' has no host");
  return e;
}

std::string Endpoint::describe() const {
  return unix_socket.empty() ? "http://" + host + ":" + std::to_string(port) : "unix:" + unix_socket;
}

ApiError::ApiError(protocol::Problem p)
    : std::runtime_error(std::to_string(p.status) + " " + p.title + ": " + p.detail), problem_(std::move(p)) {}

ApiClient::ApiClient(Endpoint endpoint, std::chrono::milliseconds timeout) : endpoint_(std::move(endpoint)), timeout_(timeout) {}

namespace {

template <class Stream>
RawResponse exchange(Stream& stream, const std::string& host, const std::string& method, const std::string& target,
                     const std::string& body, const std::map<std::string, std::string>& headers) {
  bhttp::request<bhttp::string_body> req{bhttp::string_to_verb(method), target, 11};
  req.set(bhttp::field::host, host);
  req.set(bhttp::field::user_agent, "colorlab-client");
  req.set(bhttp::field::accept, "application/json, application/problem+json");
  for (const auto& [k, v] : headers) req.set(k, v);
  if (!body.empty()) {
    if (headers.find("Content-Type") == headers.end()) req.set(bhttp::field::content_type, "application/json");
    req.body() = body;
  }
  req.keep_alive(false);
  req.prepare_payload();
  bhttp::write(stream, req);
  boost::beast::flat_buffer buffer;
  bhttp::response_parser<bhttp::string_body> parser;
  parser.body_limit(256u << 20);
  bhttp::read(stream, buffer, parser);
  auto& res = parser.get();
  RawResponse out;
  out.status = static_cast<int>(res.result_int());
  out.content_type = std::string(res[bhttp::field::content_type]);
  out.body = std::move(res.body());
  for (const auto& f : res) out.headers[std::string(f.name_string())] = std::string(f.value());
  return out;
}

}  // namespace

RawResponse ApiClient::request(const std::string& method, const std::string& target, const std::string& body,
                               const std::map<std::string, std::string>& headers) const {
  asio::io_context io;
  try {
    if (!endpoint_.unix_socket.empty()) {
      asio::local::stream_protocol::socket s(io);
      s.connect(asio::local::stream_protocol::endpoint(endpoint_.unix_socket));
      return exchange(s, "localhost", method, target, body, headers);
    }
    asio::ip::tcp::resolver resolver(io);
    asio::ip::tcp::socket s(io);
    asio::connect(s, resolver.resolve(endpoint_.host, std::to_string(endpoint_.port)));
    struct timeval tv {
      static_cast<time_t>(timeout_.count() / 1000), static_cast<suseconds_t>((timeout_.count() % 1000) * 1000)
    };
    ::setsockopt(s.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    return exchange(s, endpoint_.host, method, target, body, headers);
  } catch (const boost::system::system_error& e) {
    throw Error(ErrorClass::no_comms, "cannot talk to colorlabd at " + endpoint_.describe() + ": " + e.code().message(),
                "is colorlabd running? start it with: build/bin/colorlabd");
  }
}

nlohmann::json ApiClient::expect_json(const RawResponse& r) const {
  auto j = nlohmann::json::parse(r.body, nullptr, false);
  if (r.status < 200 || r.status >= 300) {
    protocol::Problem p;
    if (!j.is_discarded() && j.is_object()) {
      p = protocol::Problem::from_json(j);
    } else {
      p.detail = r.body;
    }
    p.status = r.status;
    throw ApiError(p);
  }
  if (j.is_discarded()) throw Error(ErrorClass::protocol_error, "colorlabd answered with invalid JSON");
  return j;
}

nlohmann::json ApiClient::get(const std::string& target) const { return expect_json(request("GET", target)); }

nlohmann::json ApiClient::post(const std::string& target, const nlohmann::json& body,
                               const std::map<std::string, std::string>& headers) const {
  return expect_json(request("POST", target, body.dump(), headers));
}

nlohmann::json ApiClient::del(const std::string& target) const { return expect_json(request("DELETE", target)); }

}  // namespace colorlab::client
