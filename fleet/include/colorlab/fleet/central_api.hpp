#pragma once
// colorlab-central's HTTP API: a bench's v1 API shape, read-only, over the central PostgreSQL and bucket
// (docs/fleet.md, "The central read API"). It reuses the daemon's pieces rather than copying them: the route
// table and its matcher (which path is a bench route, and with which methods), the access check with its key
// table and wrong-key limit, the problem+json builder, the byte-range and entity-tag rules, the export
// conversions and the record types' JSON. What central adds: GET /v1/benches, bench filters on the run list, a
// `bench` member on run documents, and a 405 `central-read-only` for anything that would change something.
#include <filesystem>

#include "colorlab/fleet/central_cache.hpp"
#include "colorlab/fleet/central_catalog.hpp"
#include "colorlab/fleet/s3.hpp"
#include "colorlab/http/message.hpp"

namespace colorlab::daemon {
class Access;
}

namespace colorlab::fleet {

struct CentralContext {
  PgPool& pool;
  S3Client& s3;
  daemon::Access* access = nullptr;  // every /v1 request is checked for the read scope
  std::string started_at;
  // The web console's files, served at / as a bench serves them (same files, same Content-Security-Policy); GET /v1
  // tells the console it is on central (read_only, its features), so it shows the Runs page across benches only.
  std::filesystem::path console_dir;
  AnswerCache answers;  // run listings and measurement pages already built (central_cache.hpp)
};

// Any thread; every error leaves as problem+json.
http::HttpResponse handle_central(CentralContext& ctx, const http::HttpRequest& req);

}  // namespace colorlab::fleet
