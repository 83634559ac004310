// S3Download: a GET driven through libcurl's multi interface from the caller's thread. The write callback only
// appends to a buffer and next() stops driving the transfer once a piece is there, so what is held stays near
// one piece (plus what one curl_multi_perform delivers); the socket's own back-pressure slows the store meanwhile.
#include <curl/curl.h>
#include <openssl/evp.h>

#include <memory>

#include "colorlab/core/error.hpp"
#include "colorlab/fleet/s3.hpp"

namespace colorlab::fleet {

namespace {

constexpr const char* kEmptySha256 = "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855";

std::size_t append(char* p, std::size_t size, std::size_t n, void* out) {
  static_cast<std::string*>(out)->append(p, size * n);
  return size * n;
}

}  // namespace

struct S3Download::Impl {
  CURLM* multi = nullptr;
  CURL* easy = nullptr;
  curl_slist* headers = nullptr;
  std::string buffer;
  bool headers_done = false;
  bool done = false;
  CURLcode result = CURLE_OK;
  EVP_MD_CTX* hash = EVP_MD_CTX_new();
  std::uint64_t delivered = 0;
  std::string what;  // "GET sha256/<hex>", for messages
  char error_buffer[CURL_ERROR_SIZE] = {};

  ~Impl() {
    if (multi && easy) curl_multi_remove_handle(multi, easy);
    if (easy) curl_easy_cleanup(easy);
    if (multi) curl_multi_cleanup(multi);
    curl_slist_free_all(headers);
    EVP_MD_CTX_free(hash);
  }

  // The end of the header block: the body (or the error document) follows.
  static std::size_t on_header(char* p, std::size_t size, std::size_t n, void* self) {
    const std::size_t len = size * n;
    if (len <= 2 && (len == 0 || p[0] == '\r' || p[0] == '\n')) static_cast<Impl*>(self)->headers_done = true;
    return len;
  }

  // Drives the transfer until `enough()` or its end.
  template <class Enough>
  void pump(Enough enough) {
    while (!done && !enough()) {
      int running = 0;
      CURLMcode mc = curl_multi_perform(multi, &running);
      if (mc != CURLM_OK) throw Error(ErrorClass::internal, std::string("curl_multi_perform: ") + curl_multi_strerror(mc));
      int queued = 0;
      while (CURLMsg* m = curl_multi_info_read(multi, &queued)) {
        if (m->msg == CURLMSG_DONE) {
          done = true;
          result = m->data.result;
        }
      }
      if (done || enough()) break;
      mc = curl_multi_poll(multi, nullptr, 0, 1000, nullptr);
      if (mc != CURLM_OK) throw Error(ErrorClass::internal, std::string("curl_multi_poll: ") + curl_multi_strerror(mc));
    }
  }

  void throw_if_broken(const std::string& endpoint) const {
    if (done && result != CURLE_OK) {
      throw Error(ErrorClass::no_comms, "S3 store " + endpoint + ": " + what + ": " + curl_easy_strerror(result),
                  "check [central] s3_endpoint and that the store runs");
    }
  }
};

S3Download::S3Download(S3Client& client, const std::string& key,
                       std::optional<std::pair<std::uint64_t, std::uint64_t>> range)
    : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  d.what = "GET " + key;
  if (!d.hash || EVP_DigestInit_ex(d.hash, EVP_sha256(), nullptr) != 1) throw Error(ErrorClass::internal, "EVP_DigestInit failed");
  d.multi = curl_multi_init();
  d.easy = curl_easy_init();
  if (!d.multi || !d.easy) throw Error(ErrorClass::internal, "curl_multi_init/curl_easy_init failed");
  CURL* c = d.easy;
  // The same request S3Client::request makes (SigV4, credentials apart from the URL, the same stall bound).
  const std::string url = client.endpoint_ + "/" + client.bucket_ + "/" + key;
  const std::string sigv4 = "aws:amz:" + client.region_ + ":s3";
  curl_easy_setopt(c, CURLOPT_URL, url.c_str());
  curl_easy_setopt(c, CURLOPT_AWS_SIGV4, sigv4.c_str());
  curl_easy_setopt(c, CURLOPT_USERNAME, client.credentials_.access_key.c_str());
  curl_easy_setopt(c, CURLOPT_PASSWORD, client.credentials_.secret_key.c_str());
  curl_easy_setopt(c, CURLOPT_NOSIGNAL, 1L);
  curl_easy_setopt(c, CURLOPT_CONNECTTIMEOUT, 10L);
  curl_easy_setopt(c, CURLOPT_LOW_SPEED_LIMIT, 1024L);
  curl_easy_setopt(c, CURLOPT_LOW_SPEED_TIME, 30L);
  curl_easy_setopt(c, CURLOPT_BUFFERSIZE, 64L * 1024);
  curl_easy_setopt(c, CURLOPT_WRITEFUNCTION, append);
  curl_easy_setopt(c, CURLOPT_WRITEDATA, &d.buffer);
  curl_easy_setopt(c, CURLOPT_HEADERFUNCTION, &Impl::on_header);
  curl_easy_setopt(c, CURLOPT_HEADERDATA, &d);
  client.set_tls(c, d.error_buffer);
  d.headers = curl_slist_append(d.headers, (std::string("x-amz-content-sha256: ") + kEmptySha256).c_str());
  if (range) {
    d.headers = curl_slist_append(
        d.headers, ("Range: bytes=" + std::to_string(range->first) + "-" + std::to_string(range->second)).c_str());
  }
  curl_easy_setopt(c, CURLOPT_HTTPHEADER, d.headers);
  curl_multi_add_handle(d.multi, c);

  d.pump([&d] { return d.headers_done && !d.buffer.empty(); });
  if (d.done) {
    if (auto tls = client.tls_failure(d.result, d.error_buffer)) {
      throw Error(ErrorClass::no_comms, "S3 store " + client.endpoint_ + ": " + d.what + ": " + *tls,
                  "[central] s3_ca_file must name the CA certificate that signed the store's certificate (docs/fleet.md)");
    }
  }
  d.throw_if_broken(client.endpoint_);
  long status = 0;
  curl_easy_getinfo(c, CURLINFO_RESPONSE_CODE, &status);
  if (status == (range ? 206 : 200)) return;
  d.pump([] { return false; });  // the rest of the error document, which names the cause
  if (status == 404) {
    throw Error(ErrorClass::not_found, "the bucket has no object " + key,
                "central's catalog names it; was the bucket emptied or changed? colorlab-ship verify on the bench");
  }
  client.refuse(d.what, S3Client::Reply{status, std::move(d.buffer)});
}

S3Download::~S3Download() = default;

std::string S3Download::next() {
  Impl& d = *impl_;
  d.pump([&d] { return d.buffer.size() >= kPiece; });
  if (d.done && d.result != CURLE_OK) {
    throw Error(ErrorClass::no_comms, "the S3 store broke off " + d.what + ": " + curl_easy_strerror(d.result));
  }
  std::string piece;
  piece.swap(d.buffer);
  EVP_DigestUpdate(d.hash, piece.data(), piece.size());
  d.delivered += piece.size();
  return piece;
}

std::uint64_t S3Download::delivered() const { return impl_->delivered; }

std::string S3Download::sha256_hex() const {
  // On a copy: the running hash goes on if more pieces come.
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> copy(EVP_MD_CTX_new(), EVP_MD_CTX_free);
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  if (!copy || EVP_MD_CTX_copy_ex(copy.get(), impl_->hash) != 1 || EVP_DigestFinal_ex(copy.get(), md, &len) != 1) {
    throw Error(ErrorClass::internal, "SHA-256 of a download failed");
  }
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned i = 0; i < len; ++i) {
    out += hex[md[i] >> 4];
    out += hex[md[i] & 15];
  }
  return out;
}

}  // namespace colorlab::fleet
