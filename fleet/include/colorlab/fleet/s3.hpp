#pragma once
// The few S3 requests shipping needs, path-style, signed with SigV4 by libcurl (CURLOPT_AWS_SIGV4). Every
// request carries x-amz-content-sha256 with the payload's real hash, so the store itself verifies the bytes
// (a SigV4 store answers 400 BadDigest on a mismatch). Keys are held only here and never appear in messages.
#include <cstdint>
#include <filesystem>
#include <memory>
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
  // The CA certificates (PEM) an https:// store's certificate must chain to, instead of the system's ([ship] and
  // [central] s3_ca_file). The certificate and its host name are verified either way; one that fails ends the
  // request as Error{no_comms} saying so.
  void set_ca_file(std::filesystem::path file) { ca_file_ = std::move(file); }

 private:
  friend class S3Download;
  struct Reply {
    long status = 0;
    std::string body;
  };
  Reply request(const std::string& method, const std::string& key, const std::filesystem::path* upload,
                const std::string& payload_sha256, const std::string& extra_header = {});
  [[noreturn]] void refuse(const std::string& what, const Reply& r) const;
  // TLS settings of every request (S3Download's too); `curl` is a CURL*.
  void set_tls(void* curl, char* error_buffer) const;
  // The error for a transfer that failed in TLS (the certificate, the CA file), or nothing for another failure.
  std::optional<std::string> tls_failure(int curl_code, const char* error_buffer) const;
  std::string endpoint_, bucket_, region_;
  std::filesystem::path ca_file_;
  S3Credentials credentials_;
  long stall_timeout_s_ = 30;
};

// The object a blob is stored under, content-addressed: the bucket's one naming of blobs, which the shipper, backups,
// restores and colorlab-central all read.
inline std::string blob_key(const std::string& sha256) { return "sha256/" + sha256; }

// One GET read piece by piece, so colorlab-central relays an object of any size holding about kPiece bytes of it
// at a time (never the whole object or range). One thread at a time; next() blocks that thread until a piece has
// come or the transfer ended (a stall below 1 KiB/s for 30 s ends it, as every request of S3Client).
class S3Download {
 public:
  static constexpr std::size_t kPiece = 256 * 1024;
  // Starts the GET and waits for the store's status: Error{not_found} on 404, and as S3Client::get_part for any
  // status other than 200 (206 with a range).
  S3Download(S3Client& client, const std::string& key, std::optional<std::pair<std::uint64_t, std::uint64_t>> range);
  ~S3Download();
  S3Download(const S3Download&) = delete;
  S3Download& operator=(const S3Download&) = delete;
  // The next piece of the body (up to about kPiece bytes), empty at its end; Error{no_comms} when the transfer broke.
  std::string next();
  // SHA-256 (hex) of every byte next() has handed out: after the last piece, the object's hash.
  std::string sha256_hex() const;
  std::uint64_t delivered() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// SHA-256 of bytes, lower-case hex.
std::string sha256_hex(const std::string& bytes);

}  // namespace colorlab::fleet
