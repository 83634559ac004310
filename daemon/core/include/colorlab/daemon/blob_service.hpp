#pragma once
// The daemon's side of the image store (issue 10): the blob store under <state_dir>/blobs, the
// frame keeper campaigns write through, the start-up check (files without a row, rows without
// their file or with the wrong size or hash: logged, recorded as a `blobs` event and kept for
// GET /v1/blobs/check; nothing is deleted), the retention setting, and the preview cache.
#include <atomic>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/campaigns/frame_keeper.hpp"
#include "colorlab/daemon/config.hpp"
#include "colorlab/store/blob_index.hpp"
#include "colorlab/store/blob_store.hpp"
#include "colorlab/store/store.hpp"

namespace colorlab::daemon {

class BlobService final : public campaigns::FrameKeeper {
 public:
  // `writer` is the daemon's one writer connection: used on the io thread only.
  BlobService(boost::asio::io_context& io, store::Store& writer, const std::filesystem::path& state_dir, BlobConfig config);
  ~BlobService() override;
  BlobService(const BlobService&) = delete;
  BlobService& operator=(const BlobService&) = delete;

  store::BlobStore& files() { return files_; }
  const BlobConfig& config() const { return config_; }

  // Starts the check on its own thread (file hashes take time; the daemon serves meanwhile). Its
  // report goes to the log and the event log; retention, when set, is applied once it is done.
  void start_check();
  // The last check: {state = "running" | "done" | "failed", …} (docs/API.md, GET /v1/blobs/check).
  nlohmann::json check_report() const;
  // Applies the retention setting now (io thread): removes the rows, references and files of blobs
  // every reference to which is older than retention_days and of a kind not kept; records what it
  // removed as a `blobs` event and returns it. With `dry_run`, only lists them.
  nlohmann::json apply_retention(bool dry_run);

  // A PNG preview of a stored blob: the one kept with it if any, else rendered once into the
  // preview cache (<state_dir>/blob-previews). Any thread.
  std::filesystem::path preview_path(store::Store& reads, const store::BlobRecord& blob);

  // campaigns::FrameKeeper
  campaigns::KeptBlob keep_bytes(const std::string& name, const std::string& kind, const std::string& media_type,
                                 const nlohmann::json& meta, std::span<const std::uint8_t> bytes) override;
  campaigns::KeptBlob keep_file(const std::string& name, const std::string& kind, const std::string& media_type,
                                const nlohmann::json& meta, const std::filesystem::path& file) override;
  campaigns::KeptBlob keep_preview(const std::string& name, const campaigns::KeptBlob& of) override;

 private:
  nlohmann::json run_check(std::vector<store::BlobRecord> rows, std::filesystem::file_time_type started);
  void check_done(nlohmann::json report);

  boost::asio::io_context& io_;
  store::Store& writer_;
  store::BlobStore files_;
  std::filesystem::path preview_dir_;
  BlobConfig config_;
  mutable std::mutex mutex_;
  nlohmann::json report_;
  std::thread check_thread_;
  std::atomic<bool> stopping_{false};
};

}  // namespace colorlab::daemon
