// colorlabd: the colour lab's measurement daemon.
#include <clocale>
#include <iostream>

#include <CLI/CLI.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/log.hpp"
#include "daemon.hpp"

int main(int argc, char** argv) {
  // libgphoto2 translates choice labels; the daemon must compare the untranslated ones.
  std::setlocale(LC_ALL, "C");
  CLI::App app{"colorlabd — measurement daemon for the colour lab (see docs/ARCHITECTURE.md)"};
  std::string config_file, listen, state;
  bool verbose = false;
  app.add_option("--config", config_file, "TOML configuration; without it, the simulated lab is started")
      ->check(CLI::ExistingFile);
  app.add_option("--listen", listen, "HOST:PORT for the HTTP API (default 127.0.0.1:8765)");
  app.add_option("--state", state, "state directory (database, socket; default ./colorlab-state)");
  app.add_flag("-v,--verbose", verbose, "debug logging");
  CLI11_PARSE(app, argc, argv);

  if (verbose) colorlab::log::set_level(colorlab::log::Level::debug);
  try {
    auto config = config_file.empty() ? colorlab::daemon::embedded_default_config()
                                      : colorlab::daemon::load_config(config_file);
    if (!listen.empty()) colorlab::daemon::apply_listen(config, listen);
    if (!state.empty()) config.state_dir = state;
    colorlab::daemon::Daemon daemon(std::move(config));
    return daemon.run();
  } catch (const colorlab::Error& e) {
    std::cerr << "colorlabd: " << e.what() << "\n";
    if (!e.hint().empty()) std::cerr << "  hint: " << e.hint() << "\n";
    return 1;
  }
}
