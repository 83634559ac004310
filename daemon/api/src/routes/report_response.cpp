#include "report_response.hpp"

#include <filesystem>

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/api/conditional.hpp"
#include "colorlab/api/problem.hpp"
#include "../content_security.hpp"

namespace colorlab::daemon {

using http::HttpRequest;
using http::HttpResponse;
using nlohmann::json;

HttpResponse report_response(ReportService* reports, const HttpRequest& req, const std::string& key,
                             const std::vector<std::string>& run_ids, const std::string& what) {
  if (!reports)
    return problem_response(503, "reports-unavailable", "Reports unavailable", "this colorlabd makes no reports");
  const auto state = reports->request(key, run_ids);
  if (state.kind == ReportService::State::Kind::failed) {
    return problem_response(500, "report-failed", "Report failed", state.error,
                            "the daemon retries a minute after a failure; its log says more");
  }
  if (state.kind == ReportService::State::Kind::generating) {
    HttpResponse g;
    g.status = 202;
    g.headers["Retry-After"] = "2";
    g.headers["Cache-Control"] = "no-store";
    g.headers["Content-Security-Policy"] = kReportPolicy;
    if (req.header("accept").value_or("").find("text/html") != std::string::npos) {
      g.content_type = "text/html; charset=utf-8";
      g.body = "<!doctype html><meta charset=utf-8><meta http-equiv=refresh content=2><link rel=icon href=\"data:,\"><title>Making the report…</title>"
               "<p>Making the report of " +
               what + "… this page reloads itself.</p>";
    } else {
      g.body = json{{"state", "generating"}, {"report", key}, {"runs", run_ids}, {"retry_after_s", 2}}.dump();
    }
    return g;
  }
  std::error_code ec;
  const auto size = std::filesystem::file_size(state.file, ec);
  if (ec) throw Error(ErrorClass::io_error, "the report of " + what + " cannot be read: " + ec.message());
  HttpResponse ok;
  const std::string etag = "\"report-" + key + "-" + std::to_string(size) + "\"";
  ok.headers["ETag"] = etag;
  ok.headers["Cache-Control"] = "no-cache";
  ok.headers["Content-Disposition"] = "inline; filename=\"report-" + key + ".html\"";
  ok.headers["Content-Security-Policy"] = kReportPolicy;
  if (auto inm = req.header("if-none-match"); inm && none_match_hits(*inm, etag)) {
    ok.status = 304;
    ok.content_type.clear();
    return ok;
  }
  ok.content_type = "text/html; charset=utf-8";
  ok.file = http::FileSpan{state.file, 0, size};
  return ok;
}

}  // namespace colorlab::daemon
