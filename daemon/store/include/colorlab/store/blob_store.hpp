#pragma once
// The content-addressed file store for frames (issue 10): <root>/ab/cdef… named by the SHA-256 of
// the bytes. A file is made durable before anything may reference it: written to a temporary file
// in its final directory, fsynced, renamed into place and the directory fsynced (daemon-design-notes
// §6.2). Rows that reference files live in SQLite (blob_index.hpp) and are written after this.
// Only the filesystem: no state but the root, so any thread may use one BlobStore.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace colorlab::store {

struct StoredFile {
  std::string sha256;
  std::uint64_t size = 0;
};

// What lies under the root that is not a finished blob: a temporary file a crash left behind while
// writing, or a name that is no SHA-256 (something someone put there).
struct StrayFile {
  std::filesystem::path path;
  std::string why;  // "partial write", "not a blob name"
};

struct BlobScan {
  std::vector<StoredFile> files;
  std::vector<StrayFile> strays;
};

class BlobStore {
 public:
  explicit BlobStore(std::filesystem::path root);

  const std::filesystem::path& root() const { return root_; }
  // Where the blob with this hash lives (or would). Error{bad_parameter} unless `sha256` is 64
  // lower-case hex digits.
  std::filesystem::path path_of(std::string_view sha256) const;

  // Durable on return; returns the SHA-256. Content that is already stored is not written again.
  // Error{io_error} when the disk refuses (nothing is left under a blob's name then).
  std::string put(std::span<const std::uint8_t> bytes);
  // The same for a file's content (a camera's raw or JPEG), read in pieces.
  std::string put_file(const std::filesystem::path& source);

  // Every file under the root, without reading their content (sizes only).
  BlobScan scan() const;
  // Removes a blob's file (retention); false when it was not there.
  bool remove(std::string_view sha256) const;

  static bool is_sha256(std::string_view s);
  // The SHA-256 of a file's bytes in hex; Error{io_error} when it cannot be read.
  static std::string hash_file(const std::filesystem::path& file);

 private:
  // Moves a finished temporary file into place (or drops it when the blob exists already).
  void publish(const std::filesystem::path& tmp, const std::string& sha256) const;
  std::filesystem::path root_;
};

}  // namespace colorlab::store
