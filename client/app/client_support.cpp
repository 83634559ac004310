#include "client_support.hpp"

#include <fstream>

#include <iostream>

#include "colorlab/core/error.hpp"

namespace colorlab::cli {

using nlohmann::json;

client::ApiClient make_client(const GlobalOptions& g) {
  client::Endpoint e;
  if (!g.socket.empty()) {
    e.unix_socket = g.socket;
  } else {
    e = client::Endpoint::from_url(g.url);
    e.ca_file = g.cacert;
  }
  return client::ApiClient(e).with_api_key(g.key);
}

void print(const GlobalOptions& g, const json& j, std::string (*human)(const json&)) {
  if (g.json) {
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << human(j);
  }
}

namespace {

// key=value → JSON value: numbers and booleans as such, everything else a string.
json parse_param_value(const std::string& text) {
  auto j = json::parse(text, nullptr, false);
  if (!j.is_discarded() && (j.is_number() || j.is_boolean() || j.is_array() || j.is_object())) return j;
  return text;
}

}  // namespace

json parse_params(const std::vector<std::string>& entries) {
  json params = json::object();
  for (const auto& p : entries) {
    auto eq = p.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw Error(ErrorClass::bad_parameter, "--param '" + p + "' is not KEY=VALUE");
    }
    params[p.substr(0, eq)] = parse_param_value(p.substr(eq + 1));
  }
  return params;
}

client::RawResponse fetch_bytes(const GlobalOptions& g, const std::string& target) {
  client::RawResponse r = make_client(g).request("GET", target);
  if (r.status >= 200 && r.status < 300) return r;
  protocol::Problem p;
  auto j = json::parse(r.body, nullptr, false);
  if (j.is_object()) {
    p = protocol::Problem::from_json(j);
  } else {
    p.detail = r.body;
  }
  p.status = r.status;
  throw client::ApiError(p);
}

void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) throw Error(ErrorClass::io_error, "cannot write " + path.string(), "check the directory exists and is writable");
  f << bytes;
  f.close();
  if (!f) throw Error(ErrorClass::io_error, "write failed for " + path.string());
}

void check_id(const std::string& id, const std::string& what, const std::string& hint) {
  if (id.empty() || id.find_first_not_of("0123456789abcdefABCDEF-") != std::string::npos)
    throw Error(ErrorClass::bad_parameter, "'" + id + "' is not " + what, hint);
}

}  // namespace colorlab::cli
