// colorlab-central: the lab's read API over the central PostgreSQL and bucket the benches ship into
// (docs/fleet.md, "The central read API"). `serve` answers a bench's v1 read routes across every bench; `keys`
// manages its API keys locally (over HTTP central changes nothing, its own keys included).
// Exit status: 0 stopped by SIGTERM/SIGINT, 1 an error (message and hint on stderr), 2 a usage error.
#include <clocale>
#include <csignal>
#include <iostream>

#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/api/access.hpp"
#include "colorlab/api/console_files.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/fleet/central_api.hpp"
#include "colorlab/fleet/central_config.hpp"
#include "colorlab/fleet/central_schema.hpp"
#include "colorlab/fleet/config.hpp"
#include "colorlab/http/server.hpp"
#include "colorlab/store/api_keys.hpp"

namespace {

namespace asio = boost::asio;
namespace fleet = colorlab::fleet;
using colorlab::Error;
using colorlab::ErrorClass;

// Central reads what colorlab-ship wrote: it never creates or migrates the schema itself.
void require_schema(fleet::PgPool& pool) {
  auto pg = pool.lease();
  const int v = fleet::central_schema_version(*pg);
  if (v == 0) {
    throw Error(ErrorClass::conflict, "the central PostgreSQL holds no colorlab schema",
                "run `colorlab-ship --config <a bench's toml> central-init` once, or check [central] postgres");
  }
  if (v < fleet::kCentralSchemaVersion) {
    throw Error(ErrorClass::conflict,
                "the central schema is version " + std::to_string(v) + "; colorlab-central needs " +
                    std::to_string(fleet::kCentralSchemaVersion),
                "upgrade the central schema: colorlab-ship central-init with this colorlab's version");
  }
  if (v > fleet::kCentralSchemaVersion) {
    throw Error(ErrorClass::conflict,
                "the central schema is version " + std::to_string(v) + ", newer than this colorlab-central (" +
                    std::to_string(fleet::kCentralSchemaVersion) + ")",
                "upgrade colorlab on the central server");
  }
}

int serve(const fleet::CentralConfig& c) {
  const bool tls = !c.tls_certificate.empty();
  colorlab::daemon::check_listener(c.listen, tls, c.allow_plaintext);
  fleet::PgPool pool(c.postgres, c.threads);
  require_schema(pool);
  fleet::S3Client s3(c.s3_endpoint, c.bucket, c.region,
                     {fleet::read_secret_file(c.access_key_file, "S3 access key"),
                      fleet::read_secret_file(c.secret_key_file, "S3 secret key")});
  s3.set_ca_file(c.s3_ca_file);

  asio::io_context io{1};
  // The keys' table is colorlabd's own (same hashes, same checks, same wrong-key limit); its one writer
  // connection records last use on this thread.
  colorlab::store::Store keys(c.keys_database());
  colorlab::daemon::Access access(keys, io.get_executor());
  fleet::CentralContext ctx{pool, s3, &access, colorlab::now_iso8601()};
  ctx.console_dir = colorlab::daemon::shipped_console_dir();

  colorlab::http::ServerOptions o;
  o.tcp_host = c.listen;
  o.tcp_port = c.port;
  o.threads = c.threads;
  o.server_name = "colorlab-central";
  o.tls_certificate = c.tls_certificate;
  o.tls_private_key = c.tls_private_key;
  colorlab::http::Server server(io, o, [&ctx](const colorlab::http::HttpRequest& req) {
    return fleet::handle_central(ctx, req);
  });
  server.start();
  const std::string url = std::string(tls ? "https" : "http") + "://" + c.listen + ":" + std::to_string(server.bound_port());
  // One JSON line on stdout: where it listens (a test or a script started it on port 0).
  std::cout << nlohmann::json{{"url", url}}.dump() << std::endl;
  colorlab::log::info("central", "serving " + url + " (read-only)");

  asio::signal_set stop(io, SIGINT, SIGTERM);
  stop.async_wait([&](const boost::system::error_code&, int) { io.stop(); });
  // Keys created or revoked with `colorlab-central keys` while it serves: SIGHUP re-reads them.
  asio::signal_set hup(io, SIGHUP);
  std::function<void(const boost::system::error_code&, int)> on_hup = [&](const boost::system::error_code& ec, int) {
    if (ec) return;
    access.reload();
    colorlab::log::info("central", "API keys re-read");
    hup.async_wait(on_hup);
  };
  hup.async_wait(on_hup);
  io.run();
  server.stop();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::setlocale(LC_ALL, "C");
  CLI::App app{"colorlab-central: the lab's read-only API over the central PostgreSQL and S3 bucket"};
  std::string config_file = "/etc/colorlab/central.toml";
  app.add_option("--config", config_file, "colorlab-central's TOML ([central] and state_dir)")->capture_default_str();
  app.set_version_flag("--version", std::string("colorlab-central ") + COLORLAB_VERSION);
  app.require_subcommand(1);
  auto* serve_cmd = app.add_subcommand("serve", "serve the read API until SIGTERM (the systemd service)");
  auto* keys = app.add_subcommand("keys", "API keys of this central server (as a bench's: read scope suffices)");
  keys->require_subcommand(1);
  std::string key_name, key_scope = "read", key_id;
  auto* create = keys->add_subcommand("create", "create a key and print it once");
  create->add_option("name", key_name, "who or what holds it")->required();
  create->add_option("--scope", key_scope, "read, control or admin (central serves reads only)")->capture_default_str();
  auto* list = keys->add_subcommand("list", "list keys (never their secrets)");
  auto* revoke = keys->add_subcommand("revoke", "revoke a key by id (a running server: send it SIGHUP)");
  revoke->add_option("id", key_id, "the key's id")->required();
  CLI11_PARSE(app, argc, argv);

  try {
    const auto config = fleet::load_central_config(config_file);
    if (serve_cmd->parsed()) return serve(config);
    colorlab::store::Store db(config.keys_database());
    colorlab::store::ApiKeyStore store(db);
    if (create->parsed()) {
      auto made = store.create(key_name, key_scope);
      nlohmann::json j = made.key.to_json();
      j["key"] = made.secret;
      std::cout << j.dump() << std::endl;
    } else if (list->parsed()) {
      nlohmann::json items = nlohmann::json::array();
      for (const auto& k : store.list()) items.push_back(k.to_json());
      std::cout << nlohmann::json{{"items", items}}.dump() << std::endl;
    } else if (revoke->parsed()) {
      std::cout << store.revoke(key_id).to_json().dump() << std::endl;
    }
    return 0;
  } catch (const Error& e) {
    std::cerr << "colorlab-central: " << e.what() << "\n";
    if (!e.hint().empty()) std::cerr << "  hint: " << e.hint() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "colorlab-central: " << e.what() << "\n";
    return 1;
  }
}
