// A whole HTTP/1.1 request as colorlabd's server reads it (daemon/http server.cpp): Beast's
// request_parser with the server's limits (16 KiB of header, protocol::kMaxRequestBody of body),
// the bytes arriving in two reads (the first input byte chooses the split), then the message turned
// into an HttpRequest and its target parsed — or the 400 problem for a target it cannot parse built —
// as the server does before any route sees it.
#include <algorithm>
#include <cctype>

#include <boost/beast/http.hpp>

#include "colorlab/http/message.hpp"
#include "colorlab/protocol/api.hpp"
#include "fuzz_support.hpp"

namespace {

namespace bhttp = boost::beast::http;

void one_input(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return;
  const std::string_view all = colorlab::fuzz::as_text(data + 1, size - 1);
  const std::size_t split = std::min<std::size_t>(data[0] * 4u, all.size());

  bhttp::request_parser<bhttp::string_body> parser;
  parser.header_limit(16 * 1024);
  parser.body_limit(colorlab::protocol::kMaxRequestBody);
  parser.eager(true);

  std::string buffer(all.substr(0, split));
  std::size_t used = 0;
  boost::beast::error_code ec;
  for (int read = 0; read < 2 && !parser.is_done(); ++read) {
    if (read == 1) buffer.append(all.substr(split));
    while (!parser.is_done() && used < buffer.size()) {
      used += parser.put(boost::asio::buffer(buffer.data() + used, buffer.size() - used), ec);
      if (ec == bhttp::error::need_more) {
        ec = {};
        break;
      }
      if (ec) return;  // the server answers 400/413/431 and closes
    }
  }
  if (!parser.is_done()) {
    // The peer closed: as Beast's read does, end of stream before any byte, else put_eof.
    if (!parser.got_some()) return;
    parser.put_eof(ec);
    if (ec || !parser.is_done()) return;
  }

  auto& msg = parser.get();
  colorlab::http::HttpRequest req;
  req.method = std::string(msg.method_string());
  req.target = std::string(msg.target());
  for (const auto& field : msg) {
    std::string name(field.name_string());
    for (auto& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    req.headers[name] = std::string(field.value());
  }
  req.body = std::move(msg.body());
  if (req.body.size() > colorlab::protocol::kMaxRequestBody) {
    std::fprintf(stderr, "fuzz: a body of %zu bytes passed the %zu-byte limit\n", req.body.size(),
                 colorlab::protocol::kMaxRequestBody);
    std::abort();
  }
  (void)msg.keep_alive();
  colorlab::fuzz::typed("parse_target", [&] {
    // The server's answer to a target it cannot parse quotes the target back (server.cpp safe_handle).
    if (!req.parse_target()) {
      (void)colorlab::http::HttpResponse::problem(400, "bad-target", "Malformed request target",
                                                  "cannot parse '" + req.target + "'");
    }
  });
}

}  // namespace

COLORLAB_FUZZ_TARGET("http_request", one_input)
