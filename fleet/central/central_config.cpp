#include "colorlab/fleet/central_config.hpp"

#include <toml++/toml.h>

#include "colorlab/core/error.hpp"

namespace colorlab::fleet {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void bad(const fs::path& file, const toml::source_region& where, const std::string& what) {
  throw Error(ErrorClass::bad_parameter, file.string() + ":" + std::to_string(where.begin.line) + ": " + what,
              "see docs/fleet.md, \"The central read API\"");
}

std::string need_string(const fs::path& file, const toml::node& node, const std::string& key) {
  auto v = node.value<std::string>();
  if (!v || v->empty()) bad(file, node.source(), "central." + key + " must be a non-empty string");
  return *v;
}

}  // namespace

CentralConfig load_central_config(const fs::path& file) {
  toml::table root;
  try {
    root = toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    throw Error(ErrorClass::bad_parameter,
                file.string() + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()),
                "see docs/fleet.md");
  }
  CentralConfig c;
  const fs::path base = file.parent_path();
  auto resolve = [&](const std::string& p) { return fs::path(p).is_absolute() ? fs::path(p) : base / p; };
  for (const auto& [key, node] : root) {
    const std::string k(key.str());
    if (k == "state_dir") c.state_dir = resolve(need_string(file, node, k));
    else if (k != "central") bad(file, node.source(), "unknown key '" + k + "' (colorlab-central reads state_dir and [central])");
  }
  auto central = root["central"].as_table();
  if (!central) {
    throw Error(ErrorClass::bad_parameter, file.string() + " has no [central] section",
                "add [central] with postgres, s3_endpoint, bucket and the key files (docs/fleet.md)");
  }
  for (const auto& [key, node] : *central) {
    const std::string k(key.str());
    if (k == "listen") c.listen = need_string(file, node, k);
    else if (k == "port") {
      auto v = node.value<std::int64_t>();
      if (!v || *v < 0 || *v > 65535) bad(file, node.source(), "central.port must be from 0 to 65535");
      c.port = static_cast<unsigned short>(*v);
    } else if (k == "threads") {
      auto v = node.value<std::int64_t>();
      if (!v || *v < 1 || *v > 256) bad(file, node.source(), "central.threads must be from 1 to 256");
      c.threads = static_cast<unsigned>(*v);
    } else if (k == "postgres") c.postgres = need_string(file, node, k);
    else if (k == "s3_endpoint") c.s3_endpoint = need_string(file, node, k);
    else if (k == "bucket") c.bucket = need_string(file, node, k);
    else if (k == "region") c.region = need_string(file, node, k);
    else if (k == "access_key_file") c.access_key_file = resolve(need_string(file, node, k));
    else if (k == "secret_key_file") c.secret_key_file = resolve(need_string(file, node, k));
    else if (k == "s3_ca_file") c.s3_ca_file = resolve(need_string(file, node, k));
    else if (k == "tls_certificate") c.tls_certificate = resolve(need_string(file, node, k));
    else if (k == "tls_private_key") c.tls_private_key = resolve(need_string(file, node, k));
    else if (k == "allow_plaintext") {
      auto v = node.value<bool>();
      if (!v) bad(file, node.source(), "central.allow_plaintext must be true or false");
      c.allow_plaintext = *v;
    } else {
      bad(file, node.source(), "unknown key 'central." + k + "'");
    }
  }
  const auto& where = central->source();
  if (c.postgres.empty()) bad(file, where, "[central] needs postgres (a libpq connection string)");
  if (c.s3_endpoint.empty() || c.bucket.empty()) bad(file, where, "[central] needs s3_endpoint and bucket");
  if (!c.s3_ca_file.empty() && c.s3_endpoint.rfind("https://", 0) != 0) {
    bad(file, where, "central.s3_ca_file is for an https:// s3_endpoint; '" + c.s3_endpoint + "' is not one");
  }
  if (c.access_key_file.empty() || c.secret_key_file.empty()) {
    bad(file, where, "[central] needs access_key_file and secret_key_file (the keys themselves never go in this file)");
  }
  if (c.tls_certificate.empty() != c.tls_private_key.empty()) {
    bad(file, where, "[central] needs both tls_certificate and tls_private_key, or neither");
  }
  return c;
}

}  // namespace colorlab::fleet
