#include "colorlab/client/api_client.hpp"

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/ssl.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http.hpp>

#include "colorlab/core/error.hpp"

#include <algorithm>
#include <functional>

namespace colorlab::client {

namespace asio = boost::asio;
namespace bhttp = boost::beast::http;
namespace ssl = boost::asio::ssl;

Endpoint Endpoint::from_url(const std::string& url) {
  Endpoint e;
  std::string rest;
  if (url.rfind("http://", 0) == 0) {
    rest = url.substr(7);
  } else if (url.rfind("https://", 0) == 0) {
    rest = url.substr(8);
    e.tls = true;
  } else {
    throw Error(ErrorClass::bad_parameter, "URL '" + url + "' must start with http:// or https://",
                "e.g. http://127.0.0.1:8765");
  }
  if (auto slash = rest.find('/'); slash != std::string::npos) rest = rest.substr(0, slash);
  std::string port_text;
  if (!rest.empty() && rest.front() == '[') {
    auto close = rest.find(']');
    if (close == std::string::npos) throw Error(ErrorClass::bad_parameter, "URL '" + url + "' has an unclosed '['");
    e.host = rest.substr(1, close - 1);
    if (close + 1 < rest.size()) {
      if (rest[close + 1] != ':') throw Error(ErrorClass::bad_parameter, "URL '" + url + "' has an invalid port");
      port_text = rest.substr(close + 2);
    }
  } else if (auto colon = rest.rfind(':'); colon != std::string::npos) {
    e.host = rest.substr(0, colon);
    port_text = rest.substr(colon + 1);
  } else {
    e.host = rest;
  }
  e.port = e.tls ? 443 : 80;
  if (!port_text.empty() || rest.ends_with(':')) {
    try {
      std::size_t used = 0;
      int p = std::stoi(port_text, &used);
      if (used != port_text.size() || p <= 0 || p > 65535) throw std::out_of_range("port");
      e.port = static_cast<unsigned short>(p);
    } catch (const std::exception&) {
      throw Error(ErrorClass::bad_parameter, "URL '" + url + "' has an invalid port");
    }
  }
  if (e.host.empty()) throw Error(ErrorClass::bad_parameter, "URL '" + url + "' has no host");
  return e;
}

std::string Endpoint::describe() const {
  if (!unix_socket.empty()) return "unix:" + unix_socket;
  std::string h = host.find(':') != std::string::npos ? "[" + host + "]" : host;
  return (tls ? "https://" : "http://") + h + ":" + std::to_string(port);
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

namespace {

void set_receive_timeout(int fd, std::chrono::milliseconds timeout) {
  struct timeval tv {
    static_cast<time_t>(timeout.count() / 1000), static_cast<suseconds_t>((timeout.count() % 1000) * 1000)
  };
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
}

// Opens the endpoint's kind of connection (Unix socket, TCP, TLS over TCP) and hands it to `use` with the
// Host to name; translates a failure to talk into Error{no_comms} saying what to check.
template <class Use>
auto with_connection(const Endpoint& endpoint, std::chrono::milliseconds timeout, Use&& use) {
  asio::io_context io;
  try {
    if (!endpoint.unix_socket.empty()) {
      asio::local::stream_protocol::socket s(io);
      s.connect(asio::local::stream_protocol::endpoint(endpoint.unix_socket));
      return use(s, std::string("localhost"));
    }
    asio::ip::tcp::resolver resolver(io);
    if (!endpoint.tls) {
      asio::ip::tcp::socket s(io);
      asio::connect(s, resolver.resolve(endpoint.host, std::to_string(endpoint.port)));
      set_receive_timeout(s.native_handle(), timeout);
      return use(s, endpoint.host);
    }
    ssl::context context(ssl::context::tls_client);
    context.set_options(ssl::context::default_workarounds | ssl::context::no_sslv2 | ssl::context::no_sslv3 |
                        ssl::context::no_tlsv1 | ssl::context::no_tlsv1_1);
    context.set_verify_mode(ssl::verify_peer);
    if (endpoint.ca_file.empty()) {
      context.set_default_verify_paths();
    } else {
      boost::system::error_code ec;
      context.load_verify_file(endpoint.ca_file, ec);
      if (ec) {
        throw Error(ErrorClass::bad_parameter, "cannot read the CA certificates in " + endpoint.ca_file + ": " + ec.message(),
                    "--cacert (COLORLAB_CACERT) takes a PEM file");
      }
    }
    ssl::stream<asio::ip::tcp::socket> stream(io, context);
    // The certificate must name the host we asked for (DNS name, or IP address in subjectAltName).
    stream.set_verify_callback(ssl::host_name_verification(endpoint.host));
    boost::system::error_code ec;
    asio::ip::make_address(endpoint.host, ec);
    if (ec) SSL_set_tlsext_host_name(stream.native_handle(), endpoint.host.c_str());  // SNI: names only
    asio::connect(stream.next_layer(), resolver.resolve(endpoint.host, std::to_string(endpoint.port)));
    set_receive_timeout(stream.next_layer().native_handle(), timeout);
    stream.handshake(ssl::stream_base::client);
    auto out = use(stream, endpoint.host);
    stream.shutdown(ec);  // the answer is complete; a peer that closes without close_notify changes nothing
    return out;
  } catch (const boost::system::system_error& e) {
    if (e.code().category() == asio::error::get_ssl_category()) {
      throw Error(ErrorClass::no_comms,
                  "TLS with colorlabd at " + endpoint.describe() + " failed: " + e.code().message(),
                  "is its certificate issued for this host and by a CA you trust? pass the CA's certificate with "
                  "--cacert FILE (or COLORLAB_CACERT)");
    }
    throw Error(ErrorClass::no_comms, "cannot talk to colorlabd at " + endpoint.describe() + ": " + e.code().message(),
                "is colorlabd running? start it with: build/bin/colorlabd");
  }
}

// A GET whose body is read as it arrives (an event stream): each piece goes to `on_data` until it returns
// false or the body ends. A refusal (not 2xx) is read whole and returned for the caller to raise.
template <class Stream>
RawResponse stream_body(Stream& stream, const std::string& host, const std::string& target,
                        const std::map<std::string, std::string>& headers,
                        const std::function<bool(std::string_view)>& on_data) {
  bhttp::request<bhttp::empty_body> req{bhttp::verb::get, target, 11};
  req.set(bhttp::field::host, host);
  req.set(bhttp::field::user_agent, "colorlab-client");
  req.set(bhttp::field::accept, "text/event-stream, application/problem+json");
  for (const auto& [k, v] : headers) req.set(k, v);
  req.keep_alive(false);
  bhttp::write(stream, req);
  boost::beast::flat_buffer buffer;
  bhttp::response_parser<bhttp::buffer_body> parser;
  parser.body_limit(boost::none);
  bhttp::read_header(stream, buffer, parser);
  RawResponse out;
  out.status = static_cast<int>(parser.get().result_int());
  out.content_type = std::string(parser.get()[bhttp::field::content_type]);
  for (const auto& f : parser.get()) out.headers[std::string(f.name_string())] = std::string(f.value());
  const bool ok = out.status >= 200 && out.status < 300;
  char piece[16384];
  while (!parser.is_done()) {
    parser.get().body().data = piece;
    parser.get().body().size = sizeof piece;
    boost::system::error_code ec;
    // read_some: whatever has arrived (an event is small), not a full buffer's worth.
    bhttp::read_some(stream, buffer, parser, ec);
    if (ec == bhttp::error::need_buffer) ec = {};
    if (ec == bhttp::error::end_of_stream || ec == asio::error::eof) break;
    if (ec) throw boost::system::system_error(ec);
    const std::string_view got(piece, sizeof piece - parser.get().body().size);
    if (!ok) {
      if (out.body.size() < (1u << 20)) out.body.append(got);
    } else if (!got.empty() && !on_data(got)) {
      break;
    }
  }
  return out;
}

}  // namespace

RawResponse ApiClient::request(const std::string& method, const std::string& target, const std::string& body,
                               const std::map<std::string, std::string>& headers) const {
  auto all = headers;
  if (!api_key_.empty() && all.find("Authorization") == all.end()) all["Authorization"] = "Bearer " + api_key_;
  return with_connection(endpoint_, timeout_, [&](auto& stream, const std::string& host) {
    return exchange(stream, host, method, target, body, all);
  });
}

void ApiClient::stream(const std::string& target, const std::function<bool(std::string_view)>& on_data,
                       const std::map<std::string, std::string>& headers) const {
  auto all = headers;
  if (!api_key_.empty() && all.find("Authorization") == all.end()) all["Authorization"] = "Bearer " + api_key_;
  // Keep-alive comments come every 15 s: a minute without a byte is a dead link.
  const auto timeout = std::max(timeout_, std::chrono::milliseconds(60000));
  RawResponse refused = with_connection(endpoint_, timeout, [&](auto& s, const std::string& host) {
    return stream_body(s, host, target, all, on_data);
  });
  if (refused.status < 200 || refused.status >= 300) (void)expect_json(refused);  // throws ApiError
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
