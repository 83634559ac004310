// colorlab: the command-line client of colorlabd, and the analysis front end.
#include <clocale>
#include <iostream>

#include <CLI/CLI.hpp>

#include "colorlab/client/api_client.hpp"
#include "colorlab/core/error.hpp"
#include "commands.hpp"
#include "queue_commands.hpp"
#include "export_commands.hpp"
#include "report_command.hpp"
#include "blob_commands.hpp"
#include "access_commands.hpp"
#include "locate_commands.hpp"
#include "doctor_command.hpp"
#include "lens_commands.hpp"
#include "scene_command.hpp"
#include "verify_command.hpp"
#include "backup_commands.hpp"
#ifdef COLORLAB_HAVE_ANALYZE
#include "colorlab/cli/analyze_command.hpp"
#endif

int main(int argc, char** argv) {
  std::setlocale(LC_ALL, "C");
  CLI::App app{"colorlab — talk to colorlabd, and analyse colour data (see README.md)"};
  app.require_subcommand(1);
  colorlab::cli::GlobalOptions global;
  app.add_option("--url", global.url, "daemon URL")->envname("COLORLAB_URL")->capture_default_str();
  app.add_option("--socket", global.socket, "daemon Unix socket (instead of --url)")->envname("COLORLAB_SOCKET");
  app.add_flag("--json", global.json, "print JSON instead of text");
  app.add_option("--key", global.key, "API key (needed beyond the Unix socket for control, admin and remote reads)")
      ->envname("COLORLAB_API_KEY");
  app.add_option("--cacert", global.cacert, "CA certificate (PEM) to verify an https:// daemon against")
      ->envname("COLORLAB_CACERT");
  colorlab::cli::add_daemon_commands(app, global);
  colorlab::cli::add_queue_commands(app, global);
  colorlab::cli::add_export_command(app, global);
  colorlab::cli::add_report_command(app, global);
  colorlab::cli::add_blob_commands(app, global);
  colorlab::cli::add_access_commands(app, global);
  colorlab::cli::add_locate_commands(app, global);
  colorlab::cli::add_doctor_command(app, global);
  colorlab::cli::add_scene_command(app, global);
  colorlab::cli::add_lens_commands(app, global);
  colorlab::cli::add_verify_command(app, global);
  colorlab::cli::add_backup_commands(app);
#ifdef COLORLAB_HAVE_ANALYZE
  colorlab::cli::add_analyze_command(app);
#endif
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const colorlab::client::ApiError& e) {
    const auto& p = e.problem();
    std::cerr << "colorlab: " << p.status << " " << p.title << ": " << p.detail << "\n";
    if (!p.hint.empty()) std::cerr << "  hint: " << p.hint << "\n";
    return 2;
  } catch (const colorlab::Error& e) {
    std::cerr << "colorlab: " << e.what() << "\n";
    if (!e.hint().empty()) std::cerr << "  hint: " << e.hint() << "\n";
    return 1;
  }
  return 0;
}
