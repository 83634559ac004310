#pragma once
// The web console's static files (HTML, CSS, JavaScript), served at the root beside the v1 API.
#include <filesystem>
#include <optional>

#include "colorlab/http/message.hpp"

namespace colorlab::daemon {

// <prefix>/share/colorlab/console next to the running binary (the build tree mirrors it), or
// $COLORLAB_CONSOLE_DIR when set (a developer editing the console in the source tree).
std::filesystem::path shipped_console_dir();

// Answers a request outside /v1 from the console's directory: "/" is index.html. Returns nothing
// for paths under the API prefix. The files are public (they hold no data; every datum comes
// through the API with the caller's key), so no access check applies to them.
std::optional<http::HttpResponse> serve_console(const http::HttpRequest& req, const std::filesystem::path& dir);

}  // namespace colorlab::daemon
