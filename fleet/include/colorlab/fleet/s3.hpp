#pragma once
// The few S3 requests shipping needs, path-style, signed with SigV4 by libcurl (CURLOPT_AWS_SIGV4). Every
// request carries x-amz-content-sha256 with the payload's real hash, so the store itself verifies the bytes
// (a SigV4 store answers 400 BadDigest on a mismatch). Keys are held only here and never appear in messages.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>

namespace colorlab::fleet {

struct S3Credentials {
  std::string access_key;
  std::string secret_key;
};

class S3Client {
 public:
  S3Client(std::string endpoint, std::string bucket, std::string region, S3Credentials credentials);

  // True when the object exists (200), false on 404. Error{no_comms} when the store cannot be reached,
  // Error{io_error} with the store's code (SignatureDoesNotMatch, InvalidAccessKeyId, ...) otherwise.
  bool exists(const std::string& key);
  // Uploads a file whose SHA-256 is `sha256_hex`; the store refuses it unless the bytes hash to that.
  void put_file(const std::string& key, const std::filesystem::path& file, const std::string& sha256_hex);
  std::string get(const std::string& key);
  // Bytes first..last (inclusive) of an object, or the whole object without a range: what colorlab-central
  // streams on. Error{not_found} when the object is missing, otherwise as exists().
  std::string get_part(const std::string& key, std::optional<std::pair<std::uint64_t, std::uint64_t>> range);
  void create_bucket();
  // A request that moves under 1 KiB/s for this long ends as Error{no_comms} (a stalled store must not hang a
  // cycle). Default 30 s; [ship] stall_timeout_s.
  void set_stall_timeout(long seconds) { stall_timeout_s_ = seconds; }
  // Deletes an object (backup rotation); a missing one is no error (S3 answers 204 either way).
  void remove(const std::string& key);

 private:
  struct Reply {
    long status = 0;
    std::string body;
  };
  Reply request(const std::string& method, const std::string& key, const std::filesystem::path* upload,
                const std::string& payload_sha256, const std::string& extra_header = {});
  [[noreturn]] void refuse(const std::string& what, const Reply& r) const;
  std::string endpoint_, bucket_, region_;
  S3Credentials credentials_;
  long stall_timeout_s_ = 30;
};

// SHA-256 of bytes, lower-case hex.
std::string sha256_hex(const std::string& bytes);

}  // namespace colorlab::fleet
