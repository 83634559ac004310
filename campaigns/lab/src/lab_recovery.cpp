// Suspend, not fail: which failures an unattended night waits out, and how it knows they are over.
#include <algorithm>
#include <cstdio>

#include <boost/asio/steady_timer.hpp>
#include <boost/asio/use_awaitable.hpp>

#include "colorlab/campaigns/lab.hpp"
#include "colorlab/campaigns/roles.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/drivers/camera/camera_instrument.hpp"
#include "colorlab/drivers/lab_capabilities.hpp"

namespace colorlab::campaigns {

namespace asio = boost::asio;
using nlohmann::json;
using drivers::Capability;

namespace {

// The capability a call needs (its role's, from the registry), for finding the instrument to bring back.
std::optional<Capability> capability_for(const std::string& call) {
  const LabCall* c = find_lab_call(call);
  if (!c || c->role.empty()) return std::nullopt;
  return capability_of(std::string(c->role));
}

bool is_lamp_condition(const Error& e) { return e.info().device_code.rfind("lamp:", 0) == 0; }

// The instrument a failed call was using, to bring back: the camera it named ({camera = id or kind}, on a lab with
// two), else of those offering the call's capability the one that is down, else the first. A lab with a GigE and a
// DSLR camera otherwise reconnected the GigE for a DSLR that had gone, reported the condition cleared, and failed
// again at every retry.
std::shared_ptr<drivers::Instrument> instrument_of_call(const InstrumentSet& instruments, const std::string& call,
                                                        const json& args) {
  const auto capability = capability_for(call);
  if (!capability) return nullptr;
  if (*capability == Capability::camera && args.is_array() && !args.empty() && args[0].is_object() &&
      args[0].contains("camera")) {
    try {
      return select_camera(instruments, args[0]["camera"]);
    } catch (const Error&) {
      // A camera no instrument is: the call refuses it itself when made again.
    }
  }
  std::shared_ptr<drivers::Instrument> first;
  for (const auto& i : instruments.all()) {
    const auto offered = i->capabilities();
    if (std::find(offered.begin(), offered.end(), *capability) == offered.end()) continue;
    if (drivers::needs_connect(i->state())) return i;
    if (!first) first = i;
  }
  return first;
}

}  // namespace

std::optional<std::string> Lab::suspend_cause(const Error& e) {
  if (is_lamp_condition(e)) return std::string("lamp");
  switch (e.cls()) {
    case ErrorClass::no_comms:
    case ErrorClass::timeout:
    case ErrorClass::coms_fail:
    // An instrument that needs a person (a meter switched off or out of remote mode) is waited for
    // like one that is gone: it is reconnected once it answers again.
    case ErrorClass::needs_operator: return std::string("instrument");
    default: return std::nullopt;
  }
}

asio::awaitable<void> Lab::wait_retry(const ExecutionControl& control) {
  auto d = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(options_.suspend.retry_s / options_.time_scale));
  co_await sleep_wall(std::max<std::chrono::steady_clock::duration>(d, std::chrono::milliseconds(200)), control);
}

asio::awaitable<void> Lab::sleep_wall(std::chrono::steady_clock::duration d, const ExecutionControl& control) {
  auto end = std::chrono::steady_clock::now() + d;
  for (;;) {
    if (control.requested()) throw Error(ErrorClass::aborted, "suspension interrupted: " + control.reason);
    auto now = std::chrono::steady_clock::now();
    if (now >= end) co_return;
    asio::steady_timer t(executor_, std::min<std::chrono::steady_clock::duration>(end - now, std::chrono::milliseconds(100)));
    co_await t.async_wait(asio::use_awaitable);
  }
}

std::vector<std::string> Lab::lit_lamps() const {
  auto lamps = find_role<drivers::LampController>("lamps");
  return lamps ? lamps->lamps_on() : std::vector<std::string>{};
}

Lab::StableLight Lab::light_now(double luminance) const {
  StableLight s;
  s.luminance = luminance;
  s.dimmer_percent = dimmer_percent_;
  s.lamps = lit_lamps();
  return s;
}

void Lab::note_stable(double luminance) {
  stable_light_ = light_now(luminance);
  aimed_since_stable_ = false;
  light_.stable(stable_light_->lamps, dimmer_percent_, luminance);
}

void Lab::check_drift(double luminance, const std::string& unit) {
  auto drift = light_.check(lit_lamps(), dimmer_percent_, luminance);
  if (!drift) return;
  std::string lit;
  for (const auto& l : drift->lamps) lit += (lit.empty() ? "" : "+") + l;
  char text[256];
  std::snprintf(text, sizeof text,
                "the light drifted: %.5g %s where %.5g was read under %s at %g %% at this aim since the lamps were found "
                "stable (%+.1f %%, more than the %g %% allowed)",
                luminance, unit.c_str(), drift->expected, lit.c_str(), dimmer_percent_, drift->change_pct,
                light_.tolerance_pct());
  ErrorInfo info;
  info.cls = ErrorClass::needs_operator;
  info.message = text;
  info.hint = "a lamp is drifting (overheating, ageing, a failing ballast); the execution waits until the light is "
              "stable again";
  info.device_code = "lamp:drift";
  throw Error(std::move(info));
}

void Lab::check_dropout(double luminance, const std::string& unit) const {
  if (!stable_light_ || stable_light_->luminance <= 0 || stable_light_->dimmer_percent <= 0) return;
  auto lamps = find_role<drivers::LampController>("lamps");
  if (!lamps || lamps->lamps_on() != stable_light_->lamps || stable_light_->lamps.empty()) return;
  // Proportional to the dimmer as a floor: a real dimmer gives more light at low settings, not less,
  // and the cabinet's floor varies by far less than the factor allowed here.
  double expected = stable_light_->luminance * dimmer_percent_ / stable_light_->dimmer_percent;
  const double fraction =
      aimed_since_stable_ ? options_.suspend.dropout_fraction_other_aim : options_.suspend.dropout_fraction;
  if (luminance >= fraction * expected) return;
  std::string lit;
  for (const auto& l : stable_light_->lamps) lit += (lit.empty() ? "" : "+") + l;
  ErrorInfo info;
  info.cls = ErrorClass::needs_operator;
  info.message = "the light dropped: " + std::to_string(luminance) + " " + unit + " where about " +
                 std::to_string(expected) + " was expected under " + lit + " at " + std::to_string(dimmer_percent_) + " %";
  info.hint = "a lamp went out or a tube failed; the execution waits for the light to come back and be stable";
  info.device_code = "lamp:dropout";
  throw Error(std::move(info));
}

asio::awaitable<json> Lab::await_recovery(const std::string& call, const json& args, const Error& cause,
                                          const ExecutionControl& control) {
  const auto& p = options_.suspend;
  auto wall = [&](double lab_s) {
    auto d = std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(lab_s / options_.time_scale));
    return std::max<std::chrono::steady_clock::duration>(d, std::chrono::milliseconds(200));
  };
  const auto started = std::chrono::steady_clock::now();
  const auto give_up = started + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                     std::chrono::duration<double>(p.max_s / options_.time_scale));
  int checks = 0;
  const auto reference = stable_light_;  // the light before it went
  // What this aim, these lamps and this dimmer level read before the condition (a drift's yardstick).
  const auto lamps_before = lit_lamps();
  const auto expected_before = light_.expected(lamps_before, dimmer_percent_);
  for (;;) {
    if (std::chrono::steady_clock::now() > give_up) throw cause;
    co_await sleep_wall(wall(p.retry_s), control);
    ++checks;
    try {
      if (is_lamp_condition(cause)) {
        // The light is back when it is stable again (a relit tube warms up first, a drifting one stops) …
        json stable = co_await wait_stable(options_.warmup, control);
        const double level = stable["luminance"].get<double>();
        // A lamp still out is "stable" too, at darkness: held to the light before the dropout.
        if (reference) {
          stable_light_ = reference;
          check_dropout(level, stable.value("unit", std::string("cd/m2")));
        }
        // A lamp that settled at a new level is not out: the new level is the yardstick from now on, and how
        // far it moved goes with the resumption.
        stable_light_ = light_now(level);
        aimed_since_stable_ = false;
        light_.settle_at(stable_light_->lamps, dimmer_percent_, level);
        // … and still there after the settle time: stable again (a straight-line fit over a window centred
        // on a drift's turning point reads as stable once), not dark, and not moved on from where it settled.
        co_await sleep_wall(wall(p.settle_s), control);
        json again = co_await wait_stable(options_.warmup, control);
        const double now = again["luminance"].get<double>();
        const std::string unit = again.value("unit", std::string("cd/m2"));
        check_dropout(now, unit);
        check_drift(now, unit);
        stable_light_ = light_now(now);
        light_.settle_at(stable_light_->lamps, dimmer_percent_, now);
        json how{
            {"condition", "lamp"},
            {"cause", cause.info().device_code},
            {"checks", checks},
            {"luminance", now},
            {"stable_level", now},
            {"lamps", stable_light_->lamps},
            {"dimmer_percent", dimmer_percent_},
        };
        if (expected_before && *expected_before > 0 && stable_light_->lamps == lamps_before) {
          how["level_before"] = *expected_before;
          how["change_pct"] = (now / *expected_before - 1) * 100;
        }
        resumed_note_ = how;
        co_return how;
      }
      auto instrument = instrument_of_call(instruments_, call, args);
      if (!instrument) {
        // Nothing offers it any more (a Spectrolino that lost its table): connect every instrument that
        // is down and look again.
        for (const auto& i : instruments_.all()) {
          if (drivers::needs_connect(i->state())) {
            instrument = i;
            break;
          }
        }
      }
      if (!instrument) co_return json{{"condition", "instrument"}, {"checks", checks}};
      co_await instrument->connect();
      // Hysteresis: a link that flaps must stay up for the settle time before measuring again.
      co_await sleep_wall(wall(p.settle_s), control);
      auto s = instrument->state();
      if (drivers::needs_connect(s)) continue;
      co_return json{{"condition", "instrument"}, {"instrument", instrument->id()}, {"checks", checks}};
    } catch (const Error& e) {
      if (e.cls() == ErrorClass::aborted && control.requested()) throw;
      log::debug("lab", "still suspended (" + std::string(e.what()) + ")");
    }
  }
}

}  // namespace colorlab::campaigns
