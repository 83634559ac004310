#pragma once
// Where a campaign keeps the frames worth keeping (the raw as captured, the averaged frame as a
// float array, the camera's own TIFF/JPEG, a PNG preview). An interface: the daemon answers it
// with its content-addressed blob store, so the engine stays free of files and SQLite.
//
// A kept blob's file is durable when keep_* returns; the row that makes it part of the run is
// written with the step that made the lab call, from the references in the call's result
// (`blobs`, see kept_blobs()), so a replayed call brings its references back from the journal.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace colorlab::campaigns {

struct KeptBlob {
  std::string sha256;
  std::string name;  // within the call; the run's name is "<call>#<seq>/<name>"
  std::string kind;  // raw, average, tiff16, tiff8, jpeg, preview
  std::string media_type;
  std::uint64_t size = 0;
  nlohmann::json meta = nlohmann::json::object();

  nlohmann::json to_json() const;
  static KeptBlob from_json(const nlohmann::json& j);
};

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

// The references a lab call's result carries (its "blobs" array); empty when it has none.
std::vector<KeptBlob> kept_blobs(const nlohmann::json& call_result);
// The media type of a camera file by its extension (image/x-adobe-dng, image/jpeg, …).
std::string media_type_of(const std::filesystem::path& file);

}  // namespace colorlab::campaigns
