#pragma once
// Plain request/response values, so routing and handlers compile without Beast.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <boost/asio/awaitable.hpp>
#include <nlohmann/json_fwd.hpp>

namespace colorlab::http {

// Who is asking, as far as the connection tells: what access control decides on.
struct Peer {
  enum class Transport {
    unix_socket,
    loopback,
    remote
  };
  Transport transport = Transport::loopback;
  bool tls = false;
  std::string address;  // "127.0.0.1:53412", or the socket path
};

struct HttpRequest {
  Peer peer;
  std::string method;  // "GET"
  std::string target;  // "/v1/runs?limit=5"
  std::string path;    // "/v1/runs"
  std::map<std::string, std::string> query;
  std::map<std::string, std::string> headers;  // lower-case names
  std::string body;

  std::optional<std::string> header(const std::string& lower_name) const;
  // Splits `target` into path and decoded query parameters; false when the target is malformed.
  bool parse_target();
};

// A byte range of a file sent as the body (blobs): the server streams it without reading it whole.
struct FileSpan {
  std::filesystem::path path;
  std::uint64_t offset = 0;
  std::uint64_t length = 0;
};

// What a streaming response (Server-Sent Events) writes to: each send is one chunk on the wire.
class StreamWriter {
 public:
  virtual ~StreamWriter() = default;
  // Returns false when the client is gone or did not take the chunk within the server's write
  // deadline: the producer should stop.
  virtual boost::asio::awaitable<bool> send(std::string_view chunk) = 0;
};
using StreamProducer = std::function<boost::asio::awaitable<void>(StreamWriter&)>;

struct LaterAnswer;

struct HttpResponse {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::map<std::string, std::string> headers;
  std::optional<FileSpan> file;  // when set, the body is this range of the file
  StreamProducer stream;         // when set, a chunked body produced until it returns
  // When set, the handler's answer is not ready: the daemon awaits this on the thread that ran the
  // handler (the io thread), which serves other requests meanwhile (a dry run's fits on the worker pool).
  std::shared_ptr<const LaterAnswer> later;

  static HttpResponse json(int status, const nlohmann::json& body);
  static HttpResponse problem(int status, const std::string& code, const std::string& title, const std::string& detail,
                              const std::string& hint = {});
};

struct LaterAnswer {
  std::function<boost::asio::awaitable<HttpResponse>()> answer;
};

using Handler = std::function<HttpResponse(const HttpRequest&)>;

// For a query value in a link the server hands back: everything but unreserved characters escaped.
std::string percent_encode(std::string_view text);

}  // namespace colorlab::http
