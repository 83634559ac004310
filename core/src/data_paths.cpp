#include "colorlab/core/data_paths.hpp"

#include <cstdlib>
#include <string>

#include "colorlab/core/error.hpp"

namespace colorlab::paths {

namespace fs = std::filesystem;

fs::path colord_dir() {
  if (const char* env = std::getenv("COLORLAB_COLORD_DIR"); env && *env) return env;
  return "/usr/share/colord";
}

fs::path colord_file(std::string_view relative) {
  fs::path p = colord_dir() / fs::path(relative);
  if (!fs::exists(p)) {
    throw Error(ErrorClass::not_found, "standard data file " + p.string() + " is missing",
                "apt-get install colord-data (or set COLORLAB_COLORD_DIR)");
  }
  return p;
}

std::optional<fs::path> shared_data_dir() {
  if (const char* env = std::getenv("COLORLAB_SHARED_DATA"); env && *env) {
    if (fs::is_directory(env)) return fs::path(env);
    return std::nullopt;
  }
  // The team keeps shared/ beside the checkout; search upward from the working directory.
  std::error_code ec;
  for (fs::path dir = fs::current_path(ec); !dir.empty(); dir = dir.parent_path()) {
    fs::path candidate = dir / "shared" / "data";
    if (fs::is_directory(candidate, ec)) return candidate;
    candidate = dir.parent_path() / "shared" / "data";
    if (fs::is_directory(candidate, ec)) return candidate;
    if (dir == dir.root_path()) break;
  }
#ifdef COLORLAB_SOURCE_DIR
  fs::path from_source = fs::path(COLORLAB_SOURCE_DIR).parent_path() / "shared" / "data";
  if (fs::is_directory(from_source, ec)) return from_source;
#endif
  return std::nullopt;
}

std::optional<fs::path> shared_data_file(std::string_view name) {
  auto dir = shared_data_dir();
  if (!dir) return std::nullopt;
  fs::path p = *dir / fs::path(name);
  if (!fs::exists(p)) return std::nullopt;
  return p;
}

fs::path python_client_dir() {
  if (const char* env = std::getenv("COLORLAB_PYTHONPATH"); env && *env) return env;
  std::error_code ec;
  const auto marker = fs::path("colorlab") / "report" / "__main__.py";
  const auto self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const auto installed = self.parent_path().parent_path() / "lib" / "python3" / "dist-packages";
    if (fs::exists(installed / marker, ec)) return installed;
  }
#ifdef COLORLAB_SOURCE_DIR
  const fs::path source = fs::path(COLORLAB_SOURCE_DIR) / "client" / "python";
  if (fs::exists(source / marker, ec)) return source;
#endif
  return {};
}

}  // namespace colorlab::paths
