#include "colorlab/daemon/blob_service.hpp"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <map>

#include <boost/asio/post.hpp>

#include "blob_preview.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"
#include "colorlab/core/log.hpp"
#include "colorlab/core/thread_priority.hpp"

namespace colorlab::daemon {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// An event's lists are bounded (a wiped disk would otherwise make one event of every blob); the
// counts are always whole and GET /v1/blobs/check has the full lists.
constexpr std::size_t kEventListCap = 100;

json capped(const json& list) {
  if (list.size() <= kEventListCap) return list;
  json out = json::array();
  for (std::size_t i = 0; i < kEventListCap; ++i) out.push_back(list[i]);
  return out;
}

// colorlab-ship's note of what central holds (docs/fleet.md); 0, keeping everything, when it never shipped or the
// note is unreadable.
std::int64_t shipped_position(const fs::path& note) {
  std::ifstream in(note);
  long long v = 0;
  if (!in || !(in >> v) || v < 0) return 0;
  return v;
}

}  // namespace

BlobService::BlobService(boost::asio::io_context& io, store::Store& writer, const fs::path& state_dir, BlobConfig config)
    : io_(io), writer_(writer), files_(state_dir / "blobs"), preview_dir_(state_dir / "blob-previews"), config_(std::move(config)) {
  report_ = json{{"state", "not started"}};
}

BlobService::~BlobService() {
  stopping_ = true;
  if (check_thread_.joinable()) check_thread_.join();
}

void BlobService::start_check() {
  if (check_thread_.joinable()) return;  // once per process
  // The rows as they are now; files written after this moment belong to steps not yet committed,
  // so the check leaves them alone.
  auto rows = store::BlobIndex(writer_).all();
  const auto started = fs::file_time_type::clock::now();
  {
    std::lock_guard lock(mutex_);
    report_ = json{{"state", "running"}, {"started_at", now_iso8601()}, {"rows", rows.size()}};
  }
  check_thread_ = std::thread([this, rows = std::move(rows), started]() mutable {
    core::become_heavy_thread("blob-check");  // hashes every file: heavy, and nobody waits on it
    json report;
    try {
      report = run_check(std::move(rows), started);
    } catch (const Error& e) {
      report = json{{"state", "failed"}, {"error", e.what()}};
    } catch (const std::exception& e) {
      report = json{{"state", "failed"}, {"error", e.what()}};
    }
    if (stopping_) return;
    boost::asio::post(io_, [this, report = std::move(report)]() mutable { check_done(std::move(report)); });
  });
}

json BlobService::run_check(std::vector<store::BlobRecord> rows, fs::file_time_type started) {
  json report{{"state", "done"},
              {"verified", config_.verify_hashes ? "sha256" : "size"},
              {"rows", rows.size()},
              {"orphans", json::array()},
              {"missing", json::array()},
              {"mismatched", json::array()},
              {"partial", json::array()}};
  {
    std::lock_guard lock(mutex_);
    report["started_at"] = report_.value("started_at", now_iso8601());
  }
  const store::BlobScan scan = files_.scan();
  std::map<std::string, std::uint64_t> on_disk;
  std::uint64_t bytes = 0;
  for (const auto& f : scan.files) {
    on_disk[f.sha256] = f.size;
    bytes += f.size;
  }
  report["files"] = scan.files.size();
  report["bytes"] = bytes;
  for (const auto& s : scan.strays) report["partial"].push_back({{"path", s.path.string()}, {"why", s.why}});

  std::map<std::string, bool> has_row;
  for (const auto& row : rows) {
    if (stopping_) return json{{"state", "failed"}, {"error", "the daemon stopped during the check"}};
    has_row[row.sha256] = true;
    auto it = on_disk.find(row.sha256);
    if (it == on_disk.end()) {
      report["missing"].push_back({{"sha256", row.sha256}, {"size", row.size}, {"media_type", row.media_type}});
      continue;
    }
    if (it->second != row.size) {
      report["mismatched"].push_back({{"sha256", row.sha256}, {"expected_size", row.size}, {"size", it->second}});
      continue;
    }
    if (config_.verify_hashes) {
      try {
        const std::string actual = store::BlobStore::hash_file(files_.path_of(row.sha256));
        if (actual != row.sha256) {
          report["mismatched"].push_back({{"sha256", row.sha256}, {"expected_size", row.size}, {"size", it->second}, {"actual_sha256", actual}});
        }
      } catch (const Error& e) {
        report["mismatched"].push_back({{"sha256", row.sha256}, {"expected_size", row.size}, {"error", e.what()}});
      }
    }
  }
  for (const auto& f : scan.files) {
    if (has_row.count(f.sha256)) continue;
    const fs::path path = files_.path_of(f.sha256);
    std::error_code ec;
    if (fs::last_write_time(path, ec) > started && !ec) continue;  // kept by a step still running
    report["orphans"].push_back({{"sha256", f.sha256}, {"size", f.size}, {"path", path.string()}});
  }
  report["finished_at"] = now_iso8601();
  report["ok"] = report["orphans"].empty() && report["missing"].empty() && report["mismatched"].empty() && report["partial"].empty();
  return report;
}

void BlobService::check_done(json report) {
  if (report.value("state", "") != "done") {
    log::warning("blobs", "the blob store check failed: " + report.value("error", std::string("?")));
  } else if (report.value("ok", false)) {
    log::info("blobs", "blob store checked: " + std::to_string(report["files"].get<std::size_t>()) + " files, all with rows and intact");
  } else {
    log::warning("blobs", "blob store check: " + std::to_string(report["orphans"].size()) + " file(s) without a row, " +
                              std::to_string(report["missing"].size()) + " row(s) whose file is missing, " +
                              std::to_string(report["mismatched"].size()) + " with the wrong size or hash, " +
                              std::to_string(report["partial"].size()) + " partial or stray file(s); nothing was deleted "
                                                                         "(GET /v1/blobs/check lists them)");
  }
  json event = report;
  event["event"] = "check";
  for (const char* list : {"orphans", "missing", "mismatched", "partial"}) {
    if (!event.contains(list)) continue;
    event[std::string(list) + "_count"] = event[list].size();
    event[list] = capped(event[list]);
  }
  try {
    writer_.append_event("blobs", event);
  } catch (const Error& e) {
    log::warning("blobs", std::string("cannot record the check: ") + e.what());
  }
  // Published after its event: whoever sees the report done finds the event in the log.
  {
    std::lock_guard lock(mutex_);
    report_ = report;
  }
  if (config_.retention_days > 0 && report.value("state", "") == "done") {
    try {
      apply_retention(false);
    } catch (const Error& e) {
      log::warning("blobs", std::string("retention not applied: ") + e.what());
    }
  }
}

json BlobService::check_report() const {
  std::lock_guard lock(mutex_);
  return report_;
}

json BlobService::apply_retention(bool dry_run) {
  json out{{"retention_days", config_.retention_days}, {"keep", config_.keep}, {"dry_run", dry_run}, {"removed", json::array()}};
  if (config_.retention_days <= 0) {
    out["note"] = "retention_days is 0: blobs are kept for ever";
    return out;
  }
  const auto cutoff = std::chrono::system_clock::now() -
                      std::chrono::duration_cast<std::chrono::system_clock::duration>(std::chrono::duration<double>(config_.retention_days * 86400));
  out["cutoff"] = iso8601_utc(cutoff);
  store::BlobIndex index(writer_);
  std::optional<std::int64_t> shipped;
  if (config_.keep_unshipped) {
    shipped = shipped_position(files_.root().parent_path() / "ship" / "shipped-position");
    out["shipped_position"] = *shipped;
  }
  auto expired = index.expired(out["cutoff"].get<std::string>(), config_.keep, shipped);
  std::uint64_t bytes = 0;
  for (const auto& b : expired) {
    out["removed"].push_back({{"sha256", b.sha256}, {"size", b.size}, {"references", b.references}});
    bytes += b.size;
  }
  out["bytes"] = bytes;
  out["count"] = expired.size();
  if (dry_run || expired.empty()) return out;
  // Rows first, in one transaction with its event: a crash before the files go leaves orphans the
  // next check reports, never a row without its file.
  json event = out;
  event["event"] = "retention";
  event["removed"] = capped(out["removed"]);
  index.remove(expired, event);
  for (const auto& b : expired) {
    try {
      files_.remove(b.sha256);
      std::error_code ec;
      fs::remove(preview_dir_ / (b.sha256 + ".png"), ec);
    } catch (const Error& e) {
      log::warning("blobs", std::string("retention: ") + e.what());
    }
  }
  log::info("blobs", "retention removed " + std::to_string(expired.size()) + " blob(s), " + std::to_string(bytes) +
                         " bytes, older than " + out["cutoff"].get<std::string>());
  return out;
}

fs::path BlobService::preview_path(store::Store& reads, const store::BlobRecord& blob) {
  if (blob.media_type == "image/png") return files_.path_of(blob.sha256);
  if (auto kept = store::BlobIndex(reads).preview_of(blob.sha256)) {
    fs::path p = files_.path_of(*kept);
    std::error_code ec;
    if (fs::exists(p, ec)) return p;
  }
  const fs::path cached = preview_dir_ / (blob.sha256 + ".png");
  std::error_code ec;
  if (fs::exists(cached, ec)) return cached;
  const fs::path source = files_.path_of(blob.sha256);
  if (!fs::exists(source, ec)) {
    throw Error(ErrorClass::not_found, "the file of blob " + blob.sha256 + " is missing", "GET /v1/blobs/check lists what the store lacks");
  }
  auto png = render_preview_png(source, blob.media_type, blob.meta);
  // A cache of what can be made again: atomic (rename) so a reader never sees half a PNG, not synced.
  fs::create_directories(preview_dir_, ec);
  static std::atomic<std::uint64_t> counter{0};
  const fs::path tmp = preview_dir_ / (".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  {
    std::ofstream out(tmp, std::ios::binary);
    out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
    if (!out) throw Error(ErrorClass::io_error, "cannot write the preview cache " + tmp.string(), "check disk space");
  }
  fs::rename(tmp, cached, ec);
  if (ec) throw Error(ErrorClass::io_error, "cannot write the preview cache " + cached.string() + ": " + ec.message());
  return cached;
}

campaigns::KeptBlob BlobService::keep_bytes(const std::string& name, const std::string& kind, const std::string& media_type,
                                            const json& meta, std::span<const std::uint8_t> bytes) {
  campaigns::KeptBlob b{files_.put(bytes), name, kind, media_type, bytes.size(), meta.is_object() ? meta : json::object()};
  return b;
}

campaigns::KeptBlob BlobService::keep_file(const std::string& name, const std::string& kind, const std::string& media_type,
                                           const json& meta, const fs::path& file) {
  const std::string sha = files_.put_file(file);
  std::error_code ec;
  const auto size = fs::file_size(files_.path_of(sha), ec);
  return campaigns::KeptBlob{sha, name, kind, media_type, static_cast<std::uint64_t>(size), meta.is_object() ? meta : json::object()};
}

campaigns::KeptBlob BlobService::keep_preview(const std::string& name, const campaigns::KeptBlob& of) {
  auto png = render_preview_png(files_.path_of(of.sha256), of.media_type, of.meta);
  return keep_bytes(name, "preview", "image/png", json{{"preview_of", of.sha256}}, png);
}

}  // namespace colorlab::daemon
