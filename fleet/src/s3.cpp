#include "colorlab/fleet/s3.hpp"

#include <curl/curl.h>
#include <openssl/evp.h>

#include <cstdio>
#include <memory>

#include "colorlab/core/error.hpp"

namespace colorlab::fleet {

namespace {

// The hash of an empty payload (HEAD, GET, bucket creation).
constexpr const char* kEmptySha256 = "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855";

std::size_t collect(char* p, std::size_t size, std::size_t n, void* out) {
  static_cast<std::string*>(out)->append(p, size * n);
  return size * n;
}

// The store's <Code> from an XML error body, for messages.
std::string error_code(const std::string& body) {
  auto a = body.find("<Code>");
  auto b = body.find("</Code>");
  if (a == std::string::npos || b == std::string::npos || b < a) return {};
  return body.substr(a + 6, b - a - 6);
}

}  // namespace

std::string sha256_hex(const std::string& bytes) {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), md, &len, EVP_sha256(), nullptr) != 1) {
    throw Error(ErrorClass::internal, "SHA-256 failed (OpenSSL EVP_Digest)");
  }
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned i = 0; i < len; ++i) {
    out += hex[md[i] >> 4];
    out += hex[md[i] & 15];
  }
  return out;
}

S3Client::S3Client(std::string endpoint, std::string bucket, std::string region, S3Credentials credentials)
    : endpoint_(std::move(endpoint)), bucket_(std::move(bucket)), region_(std::move(region)),
      credentials_(std::move(credentials)) {
  while (!endpoint_.empty() && endpoint_.back() == '/') endpoint_.pop_back();
  curl_global_init(CURL_GLOBAL_DEFAULT);
}

void S3Client::set_tls(void* curl, char* error_buffer) const {
  CURL* c = static_cast<CURL*>(curl);
  // libcurl's defaults, stated: a store's certificate and name are checked whatever the configuration says.
  curl_easy_setopt(c, CURLOPT_SSL_VERIFYPEER, 1L);
  curl_easy_setopt(c, CURLOPT_SSL_VERIFYHOST, 2L);
  if (!ca_file_.empty()) curl_easy_setopt(c, CURLOPT_CAINFO, ca_file_.c_str());
  error_buffer[0] = '\0';
  curl_easy_setopt(c, CURLOPT_ERRORBUFFER, error_buffer);
}

std::optional<std::string> S3Client::tls_failure(int curl_code, const char* error_buffer) const {
  const auto rc = static_cast<CURLcode>(curl_code);
  const std::string detail = error_buffer && *error_buffer ? error_buffer : curl_easy_strerror(rc);
  if (rc == CURLE_PEER_FAILED_VERIFICATION) {
    return "the store's TLS certificate was not verified against " +
           (ca_file_.empty() ? std::string("the system's CA certificates") : "s3_ca_file " + ca_file_.string()) +
           " (" + detail + ")";
  }
  if (rc == CURLE_SSL_CACERT_BADFILE) return "cannot use s3_ca_file " + ca_file_.string() + " (" + detail + ")";
  if (rc == CURLE_SSL_CONNECT_ERROR) return "the TLS handshake failed (" + detail + ")";
  return std::nullopt;
}

S3Client::Reply S3Client::request(const std::string& method, const std::string& key,
                                  const std::filesystem::path* upload, const std::string& payload_sha256,
                                  const std::string& extra_header) {
  std::unique_ptr<CURL, decltype(&curl_easy_cleanup)> h(curl_easy_init(), curl_easy_cleanup);
  if (!h) throw Error(ErrorClass::internal, "curl_easy_init failed");
  CURL* c = h.get();
  // Keys are sha256/<hex>: nothing in them needs percent-encoding.
  const std::string url = endpoint_ + "/" + bucket_ + (key.empty() ? "" : "/" + key);
  const std::string sigv4 = "aws:amz:" + region_ + ":s3";
  Reply reply;
  curl_easy_setopt(c, CURLOPT_URL, url.c_str());
  curl_easy_setopt(c, CURLOPT_AWS_SIGV4, sigv4.c_str());
  // Through USERNAME/PASSWORD, not "user:pass": an access key may hold ':' (Swift's tempauth account:user).
  curl_easy_setopt(c, CURLOPT_USERNAME, credentials_.access_key.c_str());
  curl_easy_setopt(c, CURLOPT_PASSWORD, credentials_.secret_key.c_str());
  curl_easy_setopt(c, CURLOPT_NOSIGNAL, 1L);
  curl_easy_setopt(c, CURLOPT_CONNECTTIMEOUT, 10L);
  // A stalled store must not hang a cycle: below 1 KiB/s for stall_timeout_s_ ends the request.
  curl_easy_setopt(c, CURLOPT_LOW_SPEED_LIMIT, 1024L);
  curl_easy_setopt(c, CURLOPT_LOW_SPEED_TIME, stall_timeout_s_);
  curl_easy_setopt(c, CURLOPT_WRITEFUNCTION, collect);
  curl_easy_setopt(c, CURLOPT_WRITEDATA, &reply.body);
  char error_buffer[CURL_ERROR_SIZE];
  set_tls(c, error_buffer);
  curl_slist* headers = nullptr;
  const std::string hash_header = "x-amz-content-sha256: " + payload_sha256;
  headers = curl_slist_append(headers, hash_header.c_str());
  if (!extra_header.empty()) headers = curl_slist_append(headers, extra_header.c_str());
  std::unique_ptr<FILE, decltype(&std::fclose)> file(nullptr, std::fclose);
  if (method == "HEAD") {
    curl_easy_setopt(c, CURLOPT_NOBODY, 1L);
  } else if (method == "DELETE") {
    curl_easy_setopt(c, CURLOPT_CUSTOMREQUEST, "DELETE");
  } else if (method == "PUT") {
    curl_easy_setopt(c, CURLOPT_UPLOAD, 1L);
    if (upload) {
      file.reset(std::fopen(upload->c_str(), "rb"));
      if (!file) {
        curl_slist_free_all(headers);
        throw Error(ErrorClass::io_error, "cannot read blob file " + upload->string());
      }
      curl_easy_setopt(c, CURLOPT_READDATA, file.get());
      curl_easy_setopt(c, CURLOPT_INFILESIZE_LARGE, static_cast<curl_off_t>(std::filesystem::file_size(*upload)));
    } else {
      curl_easy_setopt(c, CURLOPT_INFILESIZE_LARGE, static_cast<curl_off_t>(0));
    }
    // No "Expect:" override here: curl 7.88 signs every header in the list, an empty one included, and the
    // store computes the signature without it.
  }
  curl_easy_setopt(c, CURLOPT_HTTPHEADER, headers);
  CURLcode rc = curl_easy_perform(c);
  curl_slist_free_all(headers);
  if (rc == CURLE_OPERATION_TIMEDOUT) {
    throw Error(ErrorClass::no_comms,
                "S3 store " + endpoint_ + ": " + method + " " + key + " stalled (under 1 KiB/s for " +
                    std::to_string(stall_timeout_s_) + " s)",
                "the store or the link to it is stalling; the next cycle retries ([ship] stall_timeout_s)");
  }
  if (auto tls = tls_failure(rc, error_buffer)) {
    throw Error(ErrorClass::no_comms, "S3 store " + endpoint_ + ": " + method + " " + key + ": " + *tls,
                "s3_ca_file must name the CA certificate (PEM) that signed the store's certificate (unset: the "
                "system's CAs), and the certificate must name the host of s3_endpoint (docs/fleet.md, \"HTTPS "
                "object store\")");
  }
  if (rc != CURLE_OK) {
    throw Error(ErrorClass::no_comms, "S3 store " + endpoint_ + ": " + method + " " + key + ": " + curl_easy_strerror(rc),
                "check [ship] s3_endpoint and that the store runs; the next cycle retries");
  }
  curl_easy_getinfo(c, CURLINFO_RESPONSE_CODE, &reply.status);
  return reply;
}

void S3Client::refuse(const std::string& what, const Reply& r) const {
  const std::string code = error_code(r.body);
  std::string hint;
  if (r.status == 403 || code == "SignatureDoesNotMatch" || code == "InvalidAccessKeyId" || code == "AccessDenied") {
    hint = "check [ship] access_key_file and secret_key_file, and region";
  } else if (code == "NoSuchBucket") {
    hint = "create the bucket '" + bucket_ + "' in the store, or fix [ship] bucket";
  } else if (code == "BadDigest" || code == "XAmzContentSHA256Mismatch") {
    hint = "the file's bytes do not hash to its name: the bench's blob store is damaged (colorlab blobs check)";
  } else if (r.status >= 500) {
    hint = "the store is unavailable; the next cycle retries";
  }
  throw Error(r.status >= 500 ? ErrorClass::no_comms : ErrorClass::io_error,
              "S3 store refused " + what + ": HTTP " + std::to_string(r.status) + (code.empty() ? "" : " " + code), hint);
}

bool S3Client::exists(const std::string& key) {
  Reply r = request("HEAD", key, nullptr, kEmptySha256);
  if (r.status == 200) return true;
  if (r.status == 404) return false;
  // A HEAD answer has no body to name the cause: ask again with GET, whose XML error says it
  // (SignatureDoesNotMatch, InvalidAccessKeyId, NoSuchBucket).
  Reply why = request("GET", key, nullptr, kEmptySha256);
  if (why.status == r.status && !error_code(why.body).empty()) refuse("HEAD " + key, why);
  refuse("HEAD " + key, r);
}

void S3Client::put_file(const std::string& key, const std::filesystem::path& file, const std::string& sha256) {
  Reply r = request("PUT", key, &file, sha256);
  if (r.status != 200 && r.status != 201) refuse("PUT " + key, r);
}

std::string S3Client::get(const std::string& key) {
  Reply r = request("GET", key, nullptr, kEmptySha256);
  if (r.status != 200) refuse("GET " + key, r);
  return std::move(r.body);
}

std::string S3Client::get_part(const std::string& key, std::optional<std::pair<std::uint64_t, std::uint64_t>> range) {
  const std::string header =
      range ? "Range: bytes=" + std::to_string(range->first) + "-" + std::to_string(range->second) : std::string();
  Reply r = request("GET", key, nullptr, kEmptySha256, header);
  if (r.status == 404) {
    throw Error(ErrorClass::not_found, "the bucket has no object " + key,
                "central's catalog names it; was the bucket emptied or changed? colorlab-ship verify on the bench");
  }
  if (r.status != (range ? 206 : 200)) refuse("GET " + key, r);
  return std::move(r.body);
}

void S3Client::remove(const std::string& key) {
  Reply r = request("DELETE", key, nullptr, kEmptySha256);
  if (r.status != 204 && r.status != 200 && r.status != 404) refuse("DELETE " + key, r);
}

void S3Client::create_bucket() {
  Reply r = request("PUT", "", nullptr, kEmptySha256);
  if (r.status != 200 && r.status != 409) refuse("PUT bucket " + bucket_, r);
}

}  // namespace colorlab::fleet
