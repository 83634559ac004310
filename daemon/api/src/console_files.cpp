#include "colorlab/api/console_files.hpp"

#include <cstdlib>
#include <map>
#include <string>
#include <system_error>

#include "colorlab/api/conditional.hpp"
#include "colorlab/api/problem.hpp"
#include "content_security.hpp"
#include "colorlab/protocol/api.hpp"

namespace colorlab::daemon {

namespace fs = std::filesystem;

fs::path shipped_console_dir() {
  if (const char* env = std::getenv("COLORLAB_CONSOLE_DIR"); env && *env) return env;
  std::error_code ec;
  auto self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return "share/colorlab/console";
  return self.parent_path().parent_path() / "share" / "colorlab" / "console";
}

namespace {

std::string content_type_of(const fs::path& file) {
  static const std::map<std::string, std::string> types{
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".svg", "image/svg+xml"},
      {".png", "image/png"},
      {".ico", "image/x-icon"},
      {".json", "application/json"},
      {".webmanifest", "application/manifest+json"},
      {".txt", "text/plain; charset=utf-8"},
  };
  auto it = types.find(file.extension().string());
  return it == types.end() ? "application/octet-stream" : it->second;
}

// Only plain names below the console directory: no "..", no hidden files, no symlinks out of it.
std::optional<fs::path> resolve(const std::string& url_path, const fs::path& dir) {
  std::string rel = url_path.substr(1);
  if (rel.empty()) rel = "index.html";
  fs::path candidate;
  for (const auto& part : fs::path(rel)) {
    auto s = part.string();
    if (s.empty() || s == "." || s == ".." || s.front() == '.') return std::nullopt;
    candidate /= part;
  }
  std::error_code ec;
  auto full = fs::weakly_canonical(dir / candidate, ec);
  auto root = fs::weakly_canonical(dir, ec);
  if (ec) return std::nullopt;
  auto [r, f] = std::mismatch(root.begin(), root.end(), full.begin(), full.end());
  if (r != root.end()) return std::nullopt;
  if (!fs::is_regular_file(full, ec)) return std::nullopt;
  return full;
}

}  // namespace

std::optional<http::HttpResponse> serve_console(const http::HttpRequest& req, const fs::path& dir) {
  const std::string prefix(protocol::kPrefix);
  const std::string& p = req.path;
  if (p == prefix || p.rfind(prefix + "/", 0) == 0 || p.empty() || p.front() != '/') return std::nullopt;
  auto file = resolve(p, dir);
  if (!file) {
    return problem_response(404, "not_found", "Not found", "no route or console file for " + p,
                            "the API is under " + prefix + "; the console at /");
  }
  if (req.method != "GET" && req.method != "HEAD") {
    auto r = problem_response(405, "method-not-allowed", "Method not allowed",
                              req.method + " is not allowed on " + p, "allowed: GET, HEAD");
    r.headers["Allow"] = "GET, HEAD";
    return r;
  }
  std::error_code ec;
  auto size = fs::file_size(*file, ec);
  auto mtime = fs::last_write_time(*file, ec);
  if (ec) return problem_response(404, "not_found", "Not found", "console file vanished: " + p);
  const std::string etag = "\"" + std::to_string(size) + "-" +
                           std::to_string(mtime.time_since_epoch().count()) + "\"";
  http::HttpResponse r;
  r.headers["ETag"] = etag;
  // Revalidate every time: after an upgrade the browser must not mix old scripts with a new API.
  r.headers["Cache-Control"] = "no-cache";
  r.headers["X-Content-Type-Options"] = "nosniff";
  r.headers["Content-Security-Policy"] = kConsolePolicy;
  if (auto inm = req.header("if-none-match"); inm && none_match_hits(*inm, etag)) {
    r.status = 304;
    r.content_type.clear();
    return r;
  }
  r.status = 200;
  r.content_type = content_type_of(*file);
  r.file = http::FileSpan{*file, 0, size};
  return r;
}

}  // namespace colorlab::daemon
