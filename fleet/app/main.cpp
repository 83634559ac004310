// colorlab-ship: ships this bench's ended runs to the lab's PostgreSQL and S3 store (docs/fleet.md).
// Exit status: 0 done, 1 an error stopped it (message and hint on stderr), 3 a run differs between the bench and
// central (shipping stops before it until a person decides), 2 a usage error.
#include <csignal>
#include <iostream>
#include <thread>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/fleet/backup.hpp"
#include "colorlab/fleet/config.hpp"
#include "colorlab/fleet/ship_status.hpp"
#include "colorlab/fleet/shipper.hpp"

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

nlohmann::json to_json(const colorlab::fleet::CycleReport& r) {
  nlohmann::json d = nlohmann::json::array();
  for (const auto& x : r.divergences) {
    d.push_back({{"run_id", x.run_id}, {"bench_digest", x.bench_digest}, {"central_digest", x.central_digest}});
  }
  nlohmann::json s = nlohmann::json::array();
  for (const auto& x : r.superseded) {
    s.push_back({{"run_id", x.run_id}, {"bench_digest", x.bench_digest}, {"central_digest", x.central_digest}});
  }
  return {
      {"position_before", r.position_before},
      {"position_after", r.position_after},
      {"runs_shipped", r.runs_shipped},
      {"measurements", r.measurements},
      {"events", r.events},
      {"blobs_uploaded", r.blobs_uploaded},
      {"divergences", d},
      {"superseded", s},
      {"transactions", r.transactions},
      {"seconds", {
                      {"read", r.seconds.read},
                      {"read_wait", r.seconds.read_wait},
                      {"blobs", r.seconds.blobs},
                      {"copy", r.seconds.copy},
                      {"merge", r.seconds.merge},
                      {"digest", r.seconds.digest},
                      {"commit", r.seconds.commit},
                  }},
  };
}

// One cycle, its outcome noted in <state_dir>/ship/status.json for the bench to show (GET /v1/shipping).
colorlab::fleet::CycleReport noted_cycle(const colorlab::fleet::ShipConfig& config) {
  try {
    auto r = colorlab::fleet::ship_cycle(config);
    colorlab::fleet::note_cycle_ok(config, r);
    return r;
  } catch (const colorlab::Error& e) {
    colorlab::fleet::note_cycle_failed(config, e.what(), e.hint());
    throw;
  } catch (const std::exception& e) {
    colorlab::fleet::note_cycle_failed(config, e.what(), "");
    throw;
  }
}

void report_error(const colorlab::Error& e) {
  std::cerr << "colorlab-ship: " << e.what() << "\n";
  if (!e.hint().empty()) std::cerr << "  hint: " << e.hint() << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"colorlab-ship: ships this bench's ended runs to the lab's PostgreSQL and S3 store"};
  std::string config_file = "/etc/colorlab/colorlabd.toml";
  app.add_option("--config", config_file, "colorlabd's TOML, with its [ship] section")->capture_default_str();
  app.set_version_flag("--version", std::string("colorlab-ship ") + COLORLAB_SHIP_VERSION);
  app.require_subcommand(1);
  auto* init = app.add_subcommand("central-init", "create or upgrade the central schema in PostgreSQL");
  auto* once = app.add_subcommand("once", "ship what has ended, print a JSON report, exit");
  auto* run = app.add_subcommand("run", "ship every interval_s until SIGTERM (the systemd service)");
  auto* verify = app.add_subcommand("verify", "compare every shipped run's digest on the bench and central");
  auto* backup = app.add_subcommand("backup", "snapshot this bench's store into the bucket, then rotate (docs/fleet.md)");
  auto* restore = app.add_subcommand("restore", "rebuild a state directory from a snapshot in the bucket");
  std::string snapshot, into;
  restore->add_option("--snapshot", snapshot, "the snapshot's name (default: the newest)");
  restore->add_option("--into", into, "the state directory to rebuild (default: state_dir; must hold no database)");
  CLI11_PARSE(app, argc, argv);

  try {
    const auto config = colorlab::fleet::load_ship_config(config_file);
    if (init->parsed()) {
      colorlab::fleet::central_init(config);
      std::cout << "central schema is current\n";
      return 0;
    }
    if (backup->parsed()) {
      auto r = colorlab::fleet::backup(config);
      std::cout << nlohmann::json{
                       {"name", r.name},
                       {"database_key", r.database_key},
                       {"database_bytes", r.database_bytes},
                       {"last_event", r.last_event},
                       {"runs", r.runs},
                       {"blobs", r.blobs},
                       {"blobs_uploaded", r.blobs_uploaded},
                       {"blobs_missing", r.blobs_missing},
                       {"rotated_out", r.rotated_out},
                   }
                       .dump()
                << std::endl;
      return 0;
    }
    if (restore->parsed()) {
      auto r = colorlab::fleet::restore(config, snapshot, into.empty() ? config.state_dir : std::filesystem::path(into));
      std::cout << nlohmann::json{
                       {"name", r.name},
                       {"state_dir", r.state_dir.string()},
                       {"epoch", r.epoch},
                       {"next_event", r.next_event},
                       {"last_event", r.last_event},
                       {"runs", r.runs},
                       {"blobs_restored", r.blobs_restored},
                       {"blobs_missing", r.blobs_missing},
                   }
                       .dump()
                << std::endl;
      return 0;
    }
    if (once->parsed()) {
      auto r = noted_cycle(config);
      std::cout << to_json(r).dump() << std::endl;
      return r.divergences.empty() ? 0 : 3;
    }
    if (verify->parsed()) {
      auto d = colorlab::fleet::verify_shipped(config);
      nlohmann::json out = nlohmann::json::array();
      for (const auto& x : d) out.push_back({{"run_id", x.run_id}, {"bench_digest", x.bench_digest}, {"central_digest", x.central_digest}});
      std::cout << nlohmann::json{{"divergences", out}}.dump() << std::endl;
      return d.empty() ? 0 : 3;
    }
    if (run->parsed()) {
      std::signal(SIGTERM, on_signal);
      std::signal(SIGINT, on_signal);
      while (!g_stop) {
        try {
          auto r = noted_cycle(config);
          if (r.runs_shipped > 0 || !r.divergences.empty()) colorlab::log::info("ship", to_json(r).dump());
        } catch (const colorlab::Error& e) {
          // The network or central being away is the normal case for a bench: log and try again next cycle.
          colorlab::log::warning("ship", std::string(e.what()) + (e.hint().empty() ? "" : " (" + e.hint() + ")"));
        } catch (const std::exception& e) {
          colorlab::log::warning("ship", e.what());
        }
        for (double waited = 0; waited < config.interval_s && !g_stop; waited += 0.1) {
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
      }
      return 0;
    }
  } catch (const colorlab::Error& e) {
    report_error(e);
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "colorlab-ship: " << e.what() << "\n";
    return 1;
  }
  return 2;
}
