#include "colorlab/sim/lab_config.hpp"

#include <tuple>

#include <toml++/toml.h>

#include "colorlab/core/toml_json.hpp"

#include "colorlab/core/error.hpp"
#include "colorlab/verify/cabinet_toml.hpp"

namespace colorlab::sim {

namespace {

[[noreturn]] void bad(const std::filesystem::path& file, const toml::node& node, const std::string& what) {
  throw Error(ErrorClass::bad_parameter, file.string() + ":" + std::to_string(node.source().begin.line) + ": " + what,
              "see docs/simulator.md");
}

std::filesystem::path path_value(const std::filesystem::path& file, const toml::node& n, const std::string& key) {
  auto v = n.value<std::string>();
  if (!v || v->empty()) bad(file, n, key + " must be a path");
  return std::filesystem::path(*v).is_absolute() ? std::filesystem::path(*v) : file.parent_path() / *v;
}

void load_dslr(const std::filesystem::path& file, const toml::table& t, DslrLabConfig& dc) {
  for (const auto& [sk, sn] : t) {
    std::string s(sk.str());
    if (s == "enabled") {
      dc.enabled = sn.value_or(true);
    } else if (s == "id") {
      dc.id = sn.value_or(std::string("dslr"));
    } else if (s == "serial") {
      auto v = sn.value<std::string>();
      if (!v || v->empty() || v->size() > 31) bad(file, sn, "dslr.serial must be 1..31 characters");
      dc.serial = *v;
    } else if (s == "size") {
      auto a = sn.as_array();
      auto w = a && a->size() == 2 ? (*a)[0].value<int64_t>() : std::nullopt;
      auto h = a && a->size() == 2 ? (*a)[1].value<int64_t>() : std::nullopt;
      if (!w || !h || *w < 64 || *h < 64 || *w % 2 || *h % 2 || *w > 8192 || *h > 8192) {
        bad(file, sn, "dslr.size must be [width, height], even, 64..8192");
      }
      dc.width = static_cast<int>(*w);
      dc.height = static_cast<int>(*h);
    } else if (s == "pose") {
      if (auto name = sn.value<std::string>()) {
        if (*name == "seeded") dc.pose = DslrLabConfig::Pose::seeded;
        else if (*name == "square") dc.pose = DslrLabConfig::Pose::square;
        else bad(file, sn, "dslr.pose must be \"seeded\", \"square\" or a table of ChartPose fields");
      } else if (auto pt = sn.as_table()) {
        dc.pose = DslrLabConfig::Pose::given;
        auto& p = dc.given_pose;
        for (const auto& [pk, pn] : *pt) {
          std::string f(pk.str());
          auto v = pn.value<double>();
          if (!v) bad(file, pn, "dslr.pose." + f + " must be a number");
          if (f == "rotation_deg") p.rotation_deg = *v;
          else if (f == "tilt_deg") p.tilt_deg = *v;
          else if (f == "swing_deg") p.swing_deg = *v;
          else if (f == "distance_mm") p.distance_mm = *v;
          else if (f == "shift_x") p.shift_x = *v;
          else if (f == "shift_y") p.shift_y = *v;
          else if (f == "k1") p.k1 = *v;
          else if (f == "k2") p.k2 = *v;
          else if (f == "principal_dx_px") p.principal_dx_px = *v;
          else if (f == "principal_dy_px") p.principal_dy_px = *v;
          else if (f == "fy_over_fx") p.fy_over_fx = *v;
          else bad(file, pn, "unknown key dslr.pose." + f + " (rotation_deg, tilt_deg, swing_deg, distance_mm, shift_x, shift_y, k1, k2, "
                                                            "principal_dx_px, principal_dy_px, fy_over_fx)");
        }
      } else {
        bad(file, sn, "dslr.pose must be \"seeded\", \"square\" or a table of ChartPose fields");
      }
    } else if (s == "pose_seed") {
      auto v = sn.value<int64_t>();
      if (!v || *v < 0) bad(file, sn, "dslr.pose_seed must be a non-negative integer");
      dc.pose_seed = static_cast<std::uint64_t>(*v);
    } else if (s == "socket") {
      dc.socket = path_value(file, sn, "dslr.socket");
    } else if (s == "capture_dir") {
      dc.capture_dir = path_value(file, sn, "dslr.capture_dir");
    } else if (s == "transfer_s") {
      auto v = sn.value<double>();
      if (!v || *v < 0) bad(file, sn, "dslr.transfer_s must be a non-negative number of seconds");
      dc.transfer_s = *v;
    } else if (s == "faults") {
      dc.faults = toml_to_json(sn);
    } else {
      bad(file, sn, "unknown key dslr." + s);
    }
  }
}

void load_relay(const std::filesystem::path& file, const toml::table& t, RelayLabConfig& rc) {
  for (const auto& [sk, sn] : t) {
    std::string s(sk.str());
    if (s == "enabled") {
      rc.enabled = sn.value_or(false);
    } else if (s == "id") {
      rc.id = sn.value_or(std::string("relay"));
    } else if (s == "board_id") {
      auto v = sn.value<std::string>();
      if (!v || v->size() != 5) bad(file, sn, "relay.board_id must be 5 characters");
      rc.board_id = *v;
    } else if (s == "relays") {
      auto v = sn.value<int64_t>();
      if (!v || *v < 1 || *v > 8) bad(file, sn, "relay.relays must be 1..8 (USBRelay1..USBRelay8)");
      rc.relays = static_cast<int>(*v);
    } else if (s == "lamps") {
      auto lt = sn.as_table();
      if (!lt) bad(file, sn, "relay.lamps must be a table like { D65 = 1, TL84 = 2 }");
      rc.lamps.clear();
      for (const auto& [lamp, relay] : *lt) {
        auto v = relay.value<int64_t>();
        if (!v || *v < 1 || *v > 8) bad(file, relay, "relay.lamps." + std::string(lamp.str()) + " must be a relay 1..8");
        try {
          (void)lamp_from_string(std::string(lamp.str()));
        } catch (const Error& e) {
          bad(file, relay, e.info().message);
        }
        for (const auto& [other, r] : rc.lamps) {
          if (r == *v) bad(file, relay, "relay " + std::to_string(*v) + " switches both " + other + " and " + std::string(lamp.str()));
        }
        rc.lamps.emplace_back(std::string(lamp.str()), static_cast<int>(*v));
      }
    } else if (s == "socket") {
      rc.socket = path_value(file, sn, "relay.socket");
    } else if (s == "faults") {
      rc.faults = toml_to_json(sn);
    } else {
      bad(file, sn, "unknown key relay." + s);
    }
  }
  for (const auto& [lamp, relay] : rc.lamps) {
    if (relay > rc.relays) {
      throw Error(ErrorClass::bad_parameter,
                  file.string() + ": relay.lamps." + lamp + " is relay " + std::to_string(relay) +
                      " but the board has " + std::to_string(rc.relays),
                  "see docs/simulator.md");
    }
  }
}

}  // namespace

LabConfig load_lab_config(const std::filesystem::path& file) {
  toml::table root;
  try {
    root = toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    throw Error(ErrorClass::bad_parameter,
                file.string() + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()));
  }
  LabConfig c;
  auto base = file.parent_path();
  for (const auto& [key, node] : root) {
    std::string k(key.str());
    if (k == "seed") {
      auto v = node.value<int64_t>();
      if (!v || *v < 0) bad(file, node, "seed must be a non-negative integer");
      c.seed = static_cast<std::uint64_t>(*v);
    } else if (k == "time_scale") {
      auto v = node.value<double>();
      if (!v || *v <= 0) bad(file, node, "time_scale must be a positive number");
      c.time_scale = *v;
    } else if (k == "control_socket") {
      auto v = node.value<std::string>();
      if (!v) bad(file, node, "control_socket must be a path");
      c.control_socket = *v;
    } else if (k == "cabinet") {
      auto t = node.as_table();
      if (!t) bad(file, node, "[cabinet] must be a table");
      c.cabinet = verify::cabinet_from_toml(*t, file);
    } else if (k == "scene") {
      auto t = node.as_table();
      if (!t) bad(file, node, "[scene] must be a table");
      for (const auto& [sk, sn] : *t) {
        std::string s(sk.str());
        if (s == "lamps_on") {
          auto a = sn.as_array();
          if (!a) bad(file, sn, "lamps_on must be an array of lamp names");
          c.lamps_on.clear();
          for (const auto& l : *a) {
            auto name = l.value<std::string>();
            if (!name) bad(file, l, "lamp names are strings");
            c.lamps_on.push_back(*name);
          }
        } else if (s == "dimmer") {
          auto v = sn.value<double>();
          if (!v || *v < 0 || *v > 100) bad(file, sn, "dimmer must be 0..100");
          c.dimmer_percent = *v;
        } else if (s == "floor_field") {
          auto v = sn.value<std::string>();
          if (!v || (*v != "section-6.2" && *v != "geometric"))
            bad(file, sn, "scene.floor_field must be \"section-6.2\" or \"geometric\"");
          c.geometric_floor = *v == "geometric";
        } else if (s == "chart_file") {
          auto v = sn.value<std::string>();
          if (!v) bad(file, sn, "chart_file must be a path");
          c.chart_file = std::filesystem::path(*v).is_absolute() ? std::filesystem::path(*v) : base / *v;
        } else {
          bad(file, sn, "unknown key scene." + s);
        }
      }
    } else if (k == "ls110") {
      auto t = node.as_table();
      if (!t) bad(file, node, "[ls110] must be a table");
      for (const auto& [sk, sn] : *t) {
        std::string s(sk.str());
        if (s == "enabled") {
          c.ls110.enabled = sn.value_or(true);
        } else if (s == "id") {
          c.ls110.id = sn.value_or(std::string("ls110"));
        } else if (s == "aim") {
          auto a = sn.as_array();
          if (!a || a->size() != 2) bad(file, sn, "aim must be [row, col]");
          c.ls110.aim_row = static_cast<int>((*a)[0].value_or(int64_t{0}));
          c.ls110.aim_col = static_cast<int>((*a)[1].value_or(int64_t{0}));
        } else if (s == "faults") {
          c.ls110.faults = toml_to_json(sn);
        } else {
          bad(file, sn, "unknown key ls110." + s);
        }
      }
    } else if (k == "spectrolino") {
      auto t = node.as_table();
      if (!t) bad(file, node, "[spectrolino] must be a table");
      auto& sc = c.spectrolino;
      for (const auto& [sk, sn] : *t) {
        std::string s(sk.str());
        // The binding is captured through a reference of its own: clang before 16 (clang-tidy 14) cannot capture a
        // structured binding.
        auto pair = [&, &value = sn](const char* what) {
          auto a = value.as_array();
          if (!a || a->size() != 2 || !(*a)[0].is_number() || !(*a)[1].is_number()) {
            bad(file, value, std::string(what) + " must be [x_mm, y_mm]");
          }
          return std::make_pair((*a)[0].value<double>().value_or(0), (*a)[1].value<double>().value_or(0));
        };
        if (s == "enabled") {
          sc.enabled = sn.value_or(true);
        } else if (s == "id") {
          sc.id = sn.value_or(std::string("spectrolino"));
        } else if (s == "table") {
          auto v = sn.value<bool>();
          if (!v) bad(file, sn, "spectrolino.table must be true (SpectroScan T) or false (stand-alone)");
          sc.device.table = *v;
        } else if (s == "power_on_baud") {
          auto v = sn.value<int64_t>();
          if (!v || !wire::spectrolino::baud_ctt(static_cast<int>(*v))) {
            bad(file, sn, "spectrolino.power_on_baud must be a Spectrolino speed (300..57600)");
          }
          sc.device.power_on_baud = static_cast<int>(*v);
        } else if (s == "serial") {
          auto v = sn.value<int64_t>();
          if (!v || *v < 0 || *v > 65535) bad(file, sn, "spectrolino.serial must be 0..65535");
          sc.device.serial = static_cast<std::uint32_t>(*v);
        } else if (s == "filter") {
          auto v = sn.value<std::string>();
          using F = wire::spectrolino::Filter;
          if (v == "none") sc.device.filter = F::None;
          else if (v == "polarising") sc.device.filter = F::Polarising;
          else if (v == "d65") sc.device.filter = F::D65;
          else if (v == "uv_cut") sc.device.filter = F::UvCut;
          else bad(file, sn, "spectrolino.filter must be none, polarising, d65 or uv_cut");
        } else if (s == "chart_origin") {
          std::tie(sc.device.chart_origin_x_mm, sc.device.chart_origin_y_mm) = pair("chart_origin");
        } else if (s == "tile") {
          std::tie(sc.device.tile_x_mm, sc.device.tile_y_mm) = pair("tile");
        } else if (s == "head") {
          sc.head_mm = pair("head");
        } else if (s == "faults") {
          sc.faults = toml_to_json(sn);
        } else {
          bad(file, sn, "unknown key spectrolino." + s);
        }
      }
    } else if (k == "dmx") {
      auto t = node.as_table();
      if (!t) bad(file, node, "[dmx] must be a table");
      auto& dc = c.dmx;
      for (const auto& [sk, sn] : *t) {
        std::string s(sk.str());
        if (s == "enabled") {
          dc.enabled = sn.value_or(true);
        } else if (s == "id") {
          dc.id = sn.value_or(std::string("dmx"));
        } else if (s == "serial") {
          auto v = sn.value<int64_t>();
          if (!v || *v < 0 || *v > 99999999) bad(file, sn, "dmx.serial must be 0..99999999");
          dc.device.serial_decimal = static_cast<std::uint32_t>(*v);
        } else if (s == "channels") {
          auto ct = sn.as_table();
          if (!ct) bad(file, sn, "dmx.channels must be a table like { D65 = 1, dimmer = 6 }");
          dc.device.channels.clear();
          for (const auto& [target, ch] : *ct) {
            auto v = ch.value<int64_t>();
            if (!v) bad(file, ch, "dmx.channels." + std::string(target.str()) + " must be a channel number");
            dc.device.channels.push_back({static_cast<int>(*v), std::string(target.str())});
          }
          try {
            validate(dc.device);
          } catch (const Error& e) {
            bad(file, sn, e.info().message);
          }
        } else if (s == "faults") {
          dc.faults = toml_to_json(sn);
        } else {
          bad(file, sn, "unknown key dmx." + s);
        }
      }
    } else if (k == "genicam") {
      auto t = node.as_table();
      if (!t) bad(file, node, "[genicam] must be a table");
      auto& gc = c.genicam;
      for (const auto& [sk, sn] : *t) {
        std::string s(sk.str());
        if (s == "enabled") {
          gc.enabled = sn.value_or(true);
        } else if (s == "id") {
          gc.id = sn.value_or(std::string("genicam"));
        } else if (s == "address") {
          gc.address = sn.value_or(std::string("127.0.0.1"));
        } else if (s == "serial") {
          auto v = sn.value<std::string>();
          if (!v || v->empty() || v->size() > 15) bad(file, sn, "genicam.serial must be 1..15 characters");
          gc.serial = *v;
        } else if (s == "size") {
          auto a = sn.as_array();
          auto w = a && a->size() == 2 ? (*a)[0].value<int64_t>() : std::nullopt;
          auto h = a && a->size() == 2 ? (*a)[1].value<int64_t>() : std::nullopt;
          if (!w || !h || *w < 16 || *h < 16 || *w % 2 || *h % 2 || *w > 8192 || *h > 8192) {
            bad(file, sn, "genicam.size must be [width, height], even, 16..8192");
          }
          gc.width = static_cast<int>(*w);
          gc.height = static_cast<int>(*h);
        } else {
          bad(file, sn, "unknown key genicam." + s);
        }
      }
    } else if (k == "dslr") {
      auto t = node.as_table();
      if (!t) bad(file, node, "[dslr] must be a table");
      load_dslr(file, *t, c.dslr);
    } else if (k == "relay") {
      auto t = node.as_table();
      if (!t) bad(file, node, "[relay] must be a table");
      load_relay(file, *t, c.relay);
    } else {
      bad(file, node, "unknown key '" + k + "'");
    }
  }
  return c;
}

}  // namespace colorlab::sim
