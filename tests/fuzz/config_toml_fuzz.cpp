// colorlabd's configuration (daemon/core config.cpp): a whole colorlabd.toml as text, parsed by
// toml++ and read into DaemonConfig with every range and type check, as --config reads it. Every number
// config.cpp holds to a range must come out finite: a range check that lets nan through (it compares
// false both ways) would leave the daemon waiting nan seconds.
#include <cmath>

#include "colorlab/daemon/config.hpp"
#include "fuzz_support.hpp"

namespace {

void one_input(const std::uint8_t* data, std::size_t size) {
  colorlab::fuzz::typed("parse_config", [&] {
    auto c = colorlab::daemon::parse_config(colorlab::fuzz::as_text(data, size), "/etc/colorlab/colorlabd.toml");
    (void)c.database_path();
    (void)c.socket_path();
    (void)c.campaign_dir();
    const auto& k = c.campaigns;
    for (double v : {k.lamp_warmup_s, k.stable_tolerance_pct, k.stable_window_s, k.stable_interval_s, k.stable_timeout_s,
                     k.suspend_retry_s, k.suspend_settle_s, k.suspend_max_s, k.time_scale, c.access.control_lease_s,
                     c.api.stream_write_timeout_s, c.blobs.retention_days, k.crash_loop_backoff_s,
                     k.crash_loop_backoff_max_s, c.notify.timeout_s}) {
      if (!std::isfinite(v)) {
        std::fprintf(stderr, "fuzz: a range-checked setting came out %f\n", v);
        std::abort();
      }
    }
  });
}

}  // namespace

COLORLAB_FUZZ_TARGET("config_toml", one_input)
