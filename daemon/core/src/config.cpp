#include "colorlab/daemon/config.hpp"

#include <algorithm>

#include <toml++/toml.h>

#include "colorlab/core/toml_json.hpp"

#include "colorlab/core/error.hpp"
#include "colorlab/protocol/api.hpp"
#include "colorlab/verify/cabinet_toml.hpp"
#include "colorlab/verify/lens_toml.hpp"

namespace colorlab::daemon {

std::filesystem::path DaemonConfig::database_path() const { return state_dir / std::string(protocol::kDatabaseName); }

std::filesystem::path DaemonConfig::socket_path() const {
  return unix_socket ? *unix_socket : state_dir / std::string(protocol::kSocketName);
}

std::filesystem::path DaemonConfig::campaign_dir() const {
  return campaigns.directory ? *campaigns.directory : state_dir / "campaigns";
}

DaemonConfig embedded_default_config() {
  DaemonConfig c;
  c.simulator.enabled = true;
  return c;
}

void apply_listen(DaemonConfig& c, const std::string& host_port) {
  auto colon = host_port.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == host_port.size()) {
    throw Error(ErrorClass::bad_parameter, "listen address '" + host_port + "' is not HOST:PORT",
                "for example 127.0.0.1:8765");
  }
  std::string host = host_port.substr(0, colon);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  int port = 0;
  try {
    std::size_t used = 0;
    port = std::stoi(host_port.substr(colon + 1), &used);
    if (used != host_port.size() - colon - 1) throw std::invalid_argument("port");
  } catch (const std::exception&) {
    port = -1;
  }
  if (port < 0 || port > 65535) {
    throw Error(ErrorClass::bad_parameter, "listen port in '" + host_port + "' must be 0..65535");
  }
  c.listen_host = host;
  c.listen_port = static_cast<unsigned short>(port);
}

namespace {

[[noreturn]] void bad(const std::filesystem::path& file, const toml::source_region& where, const std::string& what) {
  throw Error(ErrorClass::bad_parameter,
              file.string() + ":" + std::to_string(where.begin.line) + ": " + what, "see docs/configuration.md");
}

// [blobs]: retention of the image store (docs/configuration.md).
void parse_blobs(const toml::node& node, BlobConfig& b, const std::filesystem::path& file) {
  auto t = node.as_table();
  if (!t) bad(file, node.source(), "[blobs] must be a table");
  for (const auto& [bkey, bnode] : *t) {
    std::string bk(bkey.str());
    if (bk == "retention_days") {
      auto v = bnode.value<double>();
      if (!v || !(*v >= 0 && *v <= 36500)) bad(file, bnode.source(), "blobs.retention_days must be a number from 0 (for ever) to 36500");
      b.retention_days = *v;
    } else if (bk == "keep") {
      auto arr = bnode.as_array();
      if (!arr) bad(file, bnode.source(), "blobs.keep must be a list of kinds, e.g. [\"raw\", \"average\"]");
      b.keep.clear();
      for (const auto& item : *arr) {
        auto v = item.value<std::string>();
        static const std::vector<std::string> kinds = {"raw", "average", "tiff16", "tiff8", "jpeg", "preview"};
        if (!v || std::find(kinds.begin(), kinds.end(), *v) == kinds.end()) {
          bad(file, item.source(), "blobs.keep names raw, average, tiff16, tiff8, jpeg or preview");
        }
        b.keep.push_back(*v);
      }
    } else if (bk == "verify_hashes") {
      auto v = bnode.value<bool>();
      if (!v) bad(file, bnode.source(), "blobs.verify_hashes must be true or false");
      b.verify_hashes = *v;
    } else {
      bad(file, bnode.source(), "unknown key 'blobs." + bk + "'");
    }
  }
}

// [notify]: a command (argv) and/or a webhook, each optional (docs/configuration.md, "Notifications").
void parse_notify(const toml::node& node, NotifyConfig& n, const std::filesystem::path& file) {
  auto t = node.as_table();
  if (!t) bad(file, node.source(), "[notify] must be a table");
  auto strings = [&](const toml::node& v, const std::string& key, const std::string& example) {
    auto arr = v.as_array();
    if (!arr) bad(file, v.source(), "notify." + key + " must be a list of strings, e.g. " + example);
    std::vector<std::string> out;
    for (const auto& item : *arr) {
      auto s = item.value<std::string>();
      if (!s) bad(file, item.source(), "notify." + key + " must be a list of strings, e.g. " + example);
      out.push_back(*s);
    }
    return out;
  };
  for (const auto& [nkey, nnode] : *t) {
    std::string nk(nkey.str());
    if (nk == "command") {
      n.command = strings(nnode, nk, "[\"/usr/local/bin/page-me\", \"--lab\"]");
      if (n.command.empty() || n.command.front().empty()) {
        bad(file, nnode.source(), "notify.command needs the program to run as its first element (no shell is involved)");
      }
    } else if (nk == "webhook") {
      auto v = nnode.value<std::string>();
      if (!v || !(v->starts_with("http://") || v->starts_with("https://")) || v->find_first_of(" \t\r\n") != std::string::npos) {
        bad(file, nnode.source(), "notify.webhook must be an http:// or https:// URL");
      }
      n.webhook = *v;
    } else if (nk == "timeout_s") {
      auto v = nnode.value<double>();
      if (!v || !(*v >= 0.1 && *v <= 300)) bad(file, nnode.source(), "notify.timeout_s must be a number from 0.1 to 300");
      n.timeout_s = *v;
    } else if (nk == "events") {
      n.events = strings(nnode, nk, "[\"crash-loop\", \"failed\"]");
      for (const auto& e : n.events) {
        if (e != "suspended" && e != "crash-loop" && e != "failed") {
          bad(file, nnode.source(), "notify.events names suspended, crash-loop or failed, not '" + e + "'");
        }
      }
    } else {
      bad(file, nnode.source(), "unknown key 'notify." + nk + "'");
    }
  }
}

}  // namespace

// The file, or text read from it, as a TOML table; a syntax error names the file and line.
static toml::table parse_toml(const std::filesystem::path& file, const std::optional<std::string_view>& text) {
  try {
    return text ? toml::parse(*text, file.string()) : toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    throw Error(ErrorClass::bad_parameter,
                file.string() + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()),
                "fix the TOML syntax");
  }
}

static DaemonConfig from_toml(const toml::table& root, const std::filesystem::path& file);

DaemonConfig load_config(const std::filesystem::path& file) { return from_toml(parse_toml(file, std::nullopt), file); }

DaemonConfig parse_config(std::string_view text, const std::filesystem::path& file) {
  return from_toml(parse_toml(file, text), file);
}

static DaemonConfig from_toml(const toml::table& root, const std::filesystem::path& file) {
  DaemonConfig c;
  auto base = file.parent_path();
  auto resolve = [&](const std::string& p) { return std::filesystem::path(p).is_absolute() ? std::filesystem::path(p) : base / p; };

  for (const auto& [key, node] : root) {
    std::string k(key.str());
    if (k == "state_dir") {
      auto v = node.value<std::string>();
      if (!v) bad(file, node.source(), "state_dir must be a string");
      c.state_dir = resolve(*v);
    } else if (k == "listen") {
      auto v = node.value<std::string>();
      if (!v) bad(file, node.source(), "listen must be \"HOST:PORT\"");
      apply_listen(c, *v);
    } else if (k == "unix_socket") {
      auto v = node.value<std::string>();
      if (!v) bad(file, node.source(), "unix_socket must be a path");
      c.unix_socket = resolve(*v);
    } else if (k == "simulator") {
      auto t = node.as_table();
      if (!t) bad(file, node.source(), "[simulator] must be a table");
      c.simulator.enabled = t->get("enabled") ? t->get("enabled")->value_or(true) : true;
      if (auto v = (*t)["config"].value<std::string>()) c.simulator.config = resolve(*v);
      if (auto v = (*t)["time_scale"].value<double>()) c.simulator.time_scale = *v;
      if (auto v = (*t)["seed"].value<int64_t>()) c.simulator.seed = static_cast<std::uint64_t>(*v);
    } else if (k == "campaigns") {
      auto t = node.as_table();
      if (!t) bad(file, node.source(), "[campaigns] must be a table");
      for (const auto& [ckey, cnode] : *t) {
        std::string ck(ckey.str());
        // cnode by init-capture: clang before 16 cannot capture a structured binding (the fuzz build).
        auto number = [&, &cnode = cnode](double& out, double lo, double hi) {
          auto v = cnode.value<double>();
          // Written so that nan fails too: it compares false either way, and int(nan) is undefined.
          if (!v || !(*v >= lo && *v <= hi)) {
            bad(file, cnode.source(), "campaigns." + ck + " must be a number from " + std::to_string(lo) + " to " + std::to_string(hi));
          }
          out = *v;
        };
        if (ck == "directory") {
          auto v = cnode.value<std::string>();
          if (!v) bad(file, cnode.source(), "campaigns.directory must be a path");
          c.campaigns.directory = resolve(*v);
        } else if (ck == "max_resume_attempts") {
          double v = 0;
          number(v, 1, 100);
          c.campaigns.max_resume_attempts = static_cast<int>(v);
        } else if (ck == "crash_loop_backoff_s") {
          number(c.campaigns.crash_loop_backoff_s, 0.1, 86400);
        } else if (ck == "crash_loop_backoff_max_s") {
          number(c.campaigns.crash_loop_backoff_max_s, 0.1, 7 * 86400);
        } else if (ck == "crash_loop_retries") {
          double v = 0;
          number(v, 0, 100);
          c.campaigns.crash_loop_retries = static_cast<int>(v);
        } else if (ck == "lamps_off_at_shutdown") {
          auto v = cnode.value<bool>();
          if (!v) bad(file, cnode.source(), "campaigns.lamps_off_at_shutdown must be true or false");
          c.campaigns.lamps_off_at_shutdown = *v;
        } else if (ck == "lamp_warmup_s") {
          number(c.campaigns.lamp_warmup_s, 0, 86400);
        } else if (ck == "stable_tolerance_pct") {
          number(c.campaigns.stable_tolerance_pct, 1e-4, 100);
        } else if (ck == "stable_window_s") {
          number(c.campaigns.stable_window_s, 0, 86400);
        } else if (ck == "stable_interval_s") {
          number(c.campaigns.stable_interval_s, 0.01, 3600);
        } else if (ck == "stable_timeout_s") {
          number(c.campaigns.stable_timeout_s, 0, 7 * 86400);
        } else if (ck == "suspend_retry_s") {
          number(c.campaigns.suspend_retry_s, 0, 86400);
        } else if (ck == "suspend_settle_s") {
          number(c.campaigns.suspend_settle_s, 0, 86400);
        } else if (ck == "suspend_max_s") {
          number(c.campaigns.suspend_max_s, 0, 30 * 86400);
        } else if (ck == "time_scale") {
          number(c.campaigns.time_scale, 1e-3, 1e6);
        } else {
          bad(file, cnode.source(), "unknown key 'campaigns." + ck + "'");
        }
      }
      if (c.campaigns.crash_loop_backoff_max_s < c.campaigns.crash_loop_backoff_s) {
        bad(file, node.source(), "campaigns.crash_loop_backoff_max_s must not be below campaigns.crash_loop_backoff_s");
      }
    } else if (k == "api") {
      auto t = node.as_table();
      if (!t) bad(file, node.source(), "[api] must be a table");
      for (const auto& [akey, anode] : *t) {
        std::string ak(akey.str());
        auto v = anode.value<double>();
        // anode by init-capture: clang before 16 cannot capture a structured binding (the fuzz build).
        auto in = [&, &anode = anode](double lo, double hi) {
          if (!v || !(*v >= lo && *v <= hi)) {
            bad(file, anode.source(), "api." + ak + " must be a number from " + std::to_string(lo) + " to " + std::to_string(hi));
          }
          return *v;
        };
        if (ak == "threads") {
          c.api.threads = static_cast<unsigned>(in(1, 64));
        } else if (ak == "stream_write_timeout_s") {
          c.api.stream_write_timeout_s = in(0.1, 3600);
        } else if (ak == "max_connections") {
          c.api.max_connections = static_cast<unsigned>(in(16, 100000));
        } else {
          bad(file, anode.source(), "unknown key 'api." + ak + "'");
        }
      }
    } else if (k == "priority") {
      auto t = node.as_table();
      if (!t) bad(file, node.source(), "[priority] must be a table");
      for (const auto& [pkey, pnode] : *t) {
        std::string pk(pkey.str());
        auto v = pnode.value<int64_t>();
        if (pk != "heavy_work_nice" && pk != "simulator_nice") bad(file, pnode.source(), "unknown key 'priority." + pk + "'");
        if (!v || *v < 0 || *v > 19 || !pnode.is_integer()) {
          bad(file, pnode.source(), "priority." + pk + " must be a whole number from 0 (as colorlabd) to 19 (lowest)");
        }
        (pk == "heavy_work_nice" ? c.priority.heavy_work_nice : c.priority.simulator_nice) = static_cast<int>(*v);
      }
    } else if (k == "queue") {
      auto t = node.as_table();
      if (!t) bad(file, node.source(), "[queue] must be a table");
      for (const auto& [qkey, qnode] : *t) {
        std::string qk(qkey.str());
        if (qk == "autostart") {
          auto v = qnode.value<bool>();
          if (!v) bad(file, qnode.source(), "queue.autostart must be true or false");
          c.queue.autostart = *v;
        } else {
          bad(file, qnode.source(), "unknown key 'queue." + qk + "'");
        }
      }
    } else if (k == "notify") {
      parse_notify(node, c.notify, file);
    } else if (k == "access") {
      auto t = node.as_table();
      if (!t) bad(file, node.source(), "[access] must be a table");
      for (const auto& [akey, anode] : *t) {
        std::string ak(akey.str());
        if (ak == "loopback_scope") {
          auto v = anode.value<std::string>();
          if (!v || (*v != "read" && *v != "control" && *v != "admin")) {
            bad(file, anode.source(), "access.loopback_scope must be \"read\", \"control\" or \"admin\"");
          }
          c.access.loopback_scope = *v;
        } else if (ak == "allow_plaintext") {
          auto v = anode.value<bool>();
          if (!v) bad(file, anode.source(), "access.allow_plaintext must be true or false");
          c.access.allow_plaintext = *v;
        } else if (ak == "tls_certificate" || ak == "tls_private_key") {
          auto v = anode.value<std::string>();
          if (!v || v->empty()) bad(file, anode.source(), "access." + ak + " must be the path of a PEM file");
          (ak == "tls_certificate" ? c.access.tls_certificate : c.access.tls_private_key) = resolve(*v);
        } else if (ak == "control_lease_s") {
          auto v = anode.value<double>();
          if (!v || !(*v >= 1 && *v <= 7 * 86400)) bad(file, anode.source(), "access.control_lease_s must be a number from 1 to 604800");
          c.access.control_lease_s = *v;
        } else {
          bad(file, anode.source(), "unknown key 'access." + ak + "'");
        }
      }
      if (c.access.tls_certificate.has_value() != c.access.tls_private_key.has_value()) {
        bad(file, node.source(), "[access] needs both tls_certificate and tls_private_key, or neither");
      }
    } else if (k == "cabinet") {
      // The same table colorlab-sim's lab file and `colorlab scene --lab` read: one parser, one set of refusals.
      auto t = node.as_table();
      if (!t) bad(file, node.source(), "[cabinet] must be a table");
      c.cabinet = verify::cabinet_from_toml(*t, file);
    } else if (k == "lens") {
      // The lab's lens calibrations, with the lab's other per-camera facts: the same [[lens]] parser as --lab files.
      auto a = node.as_array();
      if (!a) bad(file, node.source(), "lens must be [[lens]] tables");
      c.lenses = verify::lenses_from_toml(*a, file.string());
    } else if (k == "blobs") {
      parse_blobs(node, c.blobs, file);
    } else if (k == "ship") {
      // colorlab-ship's section (fleet/, which checks its keys); colorlabd only learns that shipping is on.
      if (!node.as_table()) bad(file, node.source(), "[ship] must be a table");
      c.blobs.keep_unshipped = true;
    } else if (k == "instrument") {
      auto arr = node.as_array();
      if (!arr) bad(file, node.source(), "instruments are [[instrument]] tables");
      for (const auto& item : *arr) {
        auto t = item.as_table();
        if (!t) bad(file, item.source(), "each [[instrument]] must be a table");
        drivers::InstrumentConfig ic;
        ic.id = (*t)["id"].value_or(std::string());
        ic.kind = (*t)["kind"].value_or(std::string());
        ic.port = (*t)["port"].value_or(std::string());
        ic.simulated = (*t)["simulated"].value_or(false);
        if (ic.id.empty() || ic.kind.empty() || ic.port.empty()) {
          bad(file, item.source(), "[[instrument]] needs id, kind and port");
        }
        if (auto opts = (*t)["options"].as_table()) ic.options = toml_to_json(*opts);
        c.instruments.push_back(std::move(ic));
      }
    } else {
      bad(file, node.source(), "unknown key '" + k + "'");
    }
  }
  return c;
}

}  // namespace colorlab::daemon
