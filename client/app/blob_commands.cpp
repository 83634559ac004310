#include "blob_commands.hpp"

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "client_support.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::cli {

using nlohmann::json;
namespace fs = std::filesystem;

namespace {

std::string format_blobs(const json& list) {
  std::ostringstream o;
  const auto& items = list.value("items", json::array());
  if (items.empty()) return "no frames kept by this run\n";
  for (const auto& b : items) {
    o << b.value("sha256", std::string()) << "  " << b.value("kind", std::string()) << "  "
      << b.value("size", 0) << " bytes  " << b.value("name", std::string()) << "  (" << b.value("step", std::string())
      << ")\n";
  }
  return o.str();
}

// The file name a download takes in a directory: the name the run gave the frame when this run is known,
// else the hash (never a path the server names).
std::string file_name(const std::string& sha, const std::string& kind) {
  const std::string ext = kind == "preview" ? ".png" : kind == "jpeg"           ? ".jpg"
                                                   : kind.rfind("tiff", 0) == 0 ? ".tif"
                                                   : kind == "average"          ? ".f4"
                                                                                : "";
  return sha + ext;
}

}  // namespace

void add_blob_commands(CLI::App& app, GlobalOptions& global) {
  auto run = std::make_shared<std::string>();
  auto* blobs = app.add_subcommand("blobs", "List the frames a run kept in the image store (raw, averages, TIFF, JPEG, previews)");
  blobs->add_option("run", *run, "run id (colorlab runs lists them)")->required();
  blobs->callback([&global, run] {
    check_id(*run, "a run id", "colorlab runs lists them");
    print(global, make_client(global).get("/v1/runs/" + *run + "/blobs"), format_blobs);
  });

  auto sha = std::make_shared<std::string>();
  auto output = std::make_shared<std::string>();
  auto preview = std::make_shared<bool>(false);
  auto* download = app.add_subcommand("download", "Download a kept frame byte for byte (colorlab blobs RUN lists them), or its PNG preview; "
                                                  "with --json before the command (needs -o): one JSON object with the file written, its size and the time taken");
  download->add_option("sha256", *sha, "the frame's SHA-256")->required();
  download->add_option("-o,--output", *output, "file to write, or a directory (default: stdout)");
  download->add_flag("--preview", *preview, "the frame's PNG preview instead of its bytes");
  download->callback([&global, sha, output, preview] {
    check_id(*sha, "a SHA-256", "colorlab blobs RUN lists a run's frames");
    // The frame's bytes and a JSON description cannot share stdout.
    if (global.json && output->empty())
      throw Error(ErrorClass::bad_parameter, "download --json describes the file it writes: give -o FILE or -o DIR",
                  "colorlab --json download SHA256 -o DIR");
    const auto started = std::chrono::steady_clock::now();
    const auto r = fetch_bytes(global, "/v1/blobs/" + *sha + (*preview ? "/preview.png" : ""));
    if (output->empty()) {
      std::cout.write(r.body.data(), static_cast<std::streamsize>(r.body.size()));
      std::cout.flush();
      return;
    }
    fs::path path = *output;
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
      std::string kind = *preview ? "preview" : "";
      for (const auto& [k, v] : r.headers) {
        if (!*preview && (k == "X-Colorlab-Dtype" || k == "x-colorlab-dtype")) kind = "average";
        if (!*preview && (k == "Content-Type" || k == "content-type")) {
          if (v == "image/jpeg") kind = "jpeg";
          if (v == "image/tiff") kind = "tiff";
        }
      }
      path /= file_name(*sha, kind);
    }
    write_bytes(path, r.body);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    json done{
        {"path", fs::absolute(path).string()},
        {"bytes", r.body.size()},
        {"sha256", *sha},
        {"preview", *preview},
        {"seconds", seconds},
    };
    print(global, done, [](const json& j) {
      return "wrote " + j["path"].get<std::string>() + " (" + std::to_string(j["bytes"].get<std::size_t>()) + " bytes)\n";
    });
  });
}

}  // namespace colorlab::cli
