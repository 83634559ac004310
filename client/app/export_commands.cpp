#include "export_commands.hpp"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <regex>

#include <strings.h>

#include "client_support.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::cli {

using nlohmann::json;
namespace fs = std::filesystem;

namespace {

struct ExportOptions {
  std::string run;
  std::string format = "json";
  std::string camera_format;
  std::string output;
};

client::RawResponse fetch(const GlobalOptions& g, const ExportOptions& o) {
  check_id(o.run, "a run id", "colorlab runs lists them");
  std::string target = "/v1/runs/" + o.run + "/export?format=" + o.format;
  if (!o.camera_format.empty()) target += "&camera_format=" + o.camera_format;
  return fetch_bytes(g, target);
}

// A directory takes the daemon's file name (Content-Disposition), never a path the header names.
fs::path target_path(const ExportOptions& o, const client::RawResponse& r) {
  fs::path out = o.output;
  std::error_code ec;
  if (!fs::is_directory(out, ec)) return out;
  std::string name;
  for (const auto& [field, value] : r.headers) {
    std::smatch m;
    if (strcasecmp(field.c_str(), "content-disposition") == 0 && std::regex_search(value, m, std::regex(R"re(filename="?([^";]+)"?)re")))
      name = fs::path(m[1].str()).filename().string();
  }
  return out / (name.empty() || name == "." || name == ".." ? o.run + "." + o.format : name);
}

}  // namespace

void add_export_command(CLI::App& app, GlobalOptions& global) {
  auto o = std::make_shared<ExportOptions>();
  auto* cmd = app.add_subcommand("export",
                                 "Write a run's measurements as a file: CSV or JSON for any run, an ArgyllCMS .ti3 "
                                 "(CGATS) for a chart-read or characterize-camera run");
  cmd->add_option("run", o->run, "run id (colorlab runs lists them)")->required();
  cmd->add_option("-f,--format", o->format, "ti3, csv or json")->check(CLI::IsMember({"ti3", "csv", "json"}))->capture_default_str();
  cmd->add_option("--camera-format", o->camera_format,
                  "for a characterize-camera .ti3: raw, tiff16, tiff8 or jpeg (default: the format the run selected)")
      ->check(CLI::IsMember({"raw", "tiff16", "tiff8", "jpeg"}));
  cmd->add_option("-o,--output", o->output, "file to write, or a directory for the daemon's file name (default: stdout)");
  cmd->callback([&global, o] {
    const auto r = fetch(global, *o);
    if (o->output.empty()) {
      std::cout.write(r.body.data(), static_cast<std::streamsize>(r.body.size()));
      std::cout.flush();
      return;
    }
    const fs::path path = target_path(*o, r);
    write_bytes(path, r.body);
    json done{{"path", path.string()}, {"bytes", r.body.size()}, {"format", o->format}, {"run", o->run}};
    print(global, done, [](const json& j) {
      return "wrote " + j["path"].get<std::string>() + " (" + std::to_string(j["bytes"].get<std::size_t>()) + " bytes)\n";
    });
  });
}

}  // namespace colorlab::cli
