#pragma once
// Where a campaign keeps the frames worth keeping (the raw as captured, the averaged frame as a
// float array, the camera's own TIFF/JPEG, a PNG preview). An interface: the daemon answers it
// with its content-addressed blob store, so the engine stays free of files and SQLite.
//
// A kept blob's file is durable when keep_* returns; the row that makes it part of the run is
// written with the step that made the lab call: the lab hands the typed references it kept during
// the call (a KeepLedger per execution) to the engine, which commits them with the call's journal entry. The call's
// result carries them as JSON too (`blobs`), for the script and for a replay.
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/core/step_records.hpp"

namespace colorlab::campaigns {

// A kept blob's reference, `name` within the call (the run's name is "<call>#<seq>/<name>").
using KeptBlob = records::BlobRef;
// The reference as a call's result carries it (its "blobs" array), for the script and the journal.
nlohmann::json blob_json(const KeptBlob& b);

// The media type of the float/integer arrays colorlab writes: raw little-endian samples, row-major,
// described by meta {dtype = "<f4" | "<u2", shape = [h, w] | [h, w, c], cfa = "RGGB" | …}.
inline constexpr const char* kArrayMediaType = "application/x-colorlab-array";

class FrameKeeper {
 public:
  virtual ~FrameKeeper() = default;
  // Durable on return; Error{io_error} when the disk refuses. Called from worker threads: an
  // implementation must be thread-safe.
  virtual KeptBlob keep_bytes(const std::string& name, const std::string& kind, const std::string& media_type,
                              const nlohmann::json& meta, std::span<const std::uint8_t> bytes) = 0;
  virtual KeptBlob keep_file(const std::string& name, const std::string& kind, const std::string& media_type,
                             const nlohmann::json& meta, const std::filesystem::path& file) = 0;
  // A PNG preview of a kept frame (kind "preview", meta.preview_of = its sha256), kept as well.
  virtual KeptBlob keep_preview(const std::string& name, const KeptBlob& of) = 0;
};

// A keeper in front of another that notes what went through it: the lab keeps a call's frames
// through one and hands the references to the engine when the call is done. Thread-safe, as the
// keeper behind it.
class KeepLedger final : public FrameKeeper {
 public:
  void set_keeper(FrameKeeper* keeper) { keeper_ = keeper; }
  FrameKeeper* keeper() const { return keeper_; }
  KeptBlob keep_bytes(const std::string& name, const std::string& kind, const std::string& media_type,
                      const nlohmann::json& meta, std::span<const std::uint8_t> bytes) override;
  KeptBlob keep_file(const std::string& name, const std::string& kind, const std::string& media_type,
                     const nlohmann::json& meta, const std::filesystem::path& file) override;
  KeptBlob keep_preview(const std::string& name, const KeptBlob& of) override;
  // What was kept since the last take, in the order it was kept; forgets it.
  std::vector<KeptBlob> take();

 private:
  KeptBlob noted(KeptBlob b);

  FrameKeeper* keeper_ = nullptr;
  std::mutex mutex_;
  std::vector<KeptBlob> kept_;
};

// The media type of a camera file by its extension (image/x-adobe-dng, image/jpeg, …).
std::string media_type_of(const std::filesystem::path& file);

}  // namespace colorlab::campaigns
