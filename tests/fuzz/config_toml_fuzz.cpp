// colorlabd's configuration (daemon/core config.cpp): a whole colorlabd.toml as text, parsed by
// toml++ and read into DaemonConfig with every range and type check, as --config reads it.
#include "colorlab/daemon/config.hpp"
#include "fuzz_support.hpp"

namespace {

void one_input(const std::uint8_t* data, std::size_t size) {
  colorlab::fuzz::typed("parse_config", [&] {
    auto c = colorlab::daemon::parse_config(colorlab::fuzz::as_text(data, size), "/etc/colorlab/colorlabd.toml");
    (void)c.database_path();
    (void)c.socket_path();
    (void)c.campaign_dir();
  });
}

}  // namespace

COLORLAB_FUZZ_TARGET("config_toml", one_input)
