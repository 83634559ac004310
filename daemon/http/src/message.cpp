#include "colorlab/http/message.hpp"

#include <cctype>

#include <nlohmann/json.hpp>

#include "colorlab/protocol/api.hpp"
#include "colorlab/protocol/problem.hpp"

namespace colorlab::http {

std::optional<std::string> HttpRequest::header(const std::string& lower_name) const {
  auto it = headers.find(lower_name);
  if (it == headers.end()) return std::nullopt;
  return it->second;
}

namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool percent_decode(std::string_view in, std::string& out) {
  out.clear();
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (in[i] == '%') {
      if (i + 2 >= in.size()) return false;
      int hi = hex_value(in[i + 1]), lo = hex_value(in[i + 2]);
      if (hi < 0 || lo < 0) return false;
      out += static_cast<char>(hi * 16 + lo);
      i += 2;
    } else if (in[i] == '+') {
      out += ' ';
    } else {
      out += in[i];
    }
  }
  return true;
}

}  // namespace

bool HttpRequest::parse_target() {
  if (target.empty() || target[0] != '/') return false;
  auto q = target.find('?');
  if (!percent_decode(std::string_view(target).substr(0, q), path)) return false;
  query.clear();
  if (q == std::string::npos) return true;
  std::string_view rest = std::string_view(target).substr(q + 1);
  while (!rest.empty()) {
    auto amp = rest.find('&');
    std::string_view pair = rest.substr(0, amp);
    auto eq = pair.find('=');
    std::string key, value;
    if (!percent_decode(pair.substr(0, eq), key)) return false;
    if (eq != std::string_view::npos && !percent_decode(pair.substr(eq + 1), value)) return false;
    if (!key.empty()) query[key] = value;
    if (amp == std::string_view::npos) break;
    rest.remove_prefix(amp + 1);
  }
  return true;
}

HttpResponse HttpResponse::json(int status, const nlohmann::json& body) {
  HttpResponse r;
  r.status = status;
  r.content_type = std::string(protocol::kContentJson);
  r.body = body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);  // a path quoted back may not be UTF-8
  return r;
}

HttpResponse HttpResponse::problem(int status, const std::string& code, const std::string& title,
                                   const std::string& detail, const std::string& hint) {
  const auto p = protocol::problem_for_status(status, code, title, detail, hint);
  HttpResponse r;
  r.status = status;
  r.content_type = std::string(protocol::kContentProblem);
  // A detail may quote the client's bytes (a target that is not UTF-8): replaced, never a throw.
  r.body = p.to_json().dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return r;
}

std::string percent_encode(std::string_view text) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : text) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~') {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  return out;
}

}  // namespace colorlab::http
