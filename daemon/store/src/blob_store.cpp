#include "colorlab/store/blob_store.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <memory>
#include <utility>

#include <openssl/evp.h>

#include "colorlab/core/error.hpp"

namespace colorlab::store {

namespace fs = std::filesystem;

namespace {

constexpr const char* kTempPrefix = ".tmp-";
constexpr std::size_t kChunk = 1 << 20;

Error io_failure(const std::string& what, int err) {
  return Error(ErrorClass::io_error, what + ": " + std::strerror(err), "check disk space and permissions of the state directory");
}

struct Digest {
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx{EVP_MD_CTX_new(), &EVP_MD_CTX_free};
  Digest() {
    if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1) throw Error(ErrorClass::internal, "OpenSSL cannot start a SHA-256");
  }
  void update(const void* data, std::size_t n) {
    if (EVP_DigestUpdate(ctx.get(), data, n) != 1) throw Error(ErrorClass::internal, "OpenSSL SHA-256 update failed");
  }
  std::string hex() {
    unsigned char md[EVP_MAX_MD_SIZE];
    unsigned int n = 0;
    if (EVP_DigestFinal_ex(ctx.get(), md, &n) != 1) throw Error(ErrorClass::internal, "OpenSSL SHA-256 final failed");
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    out.reserve(2 * n);
    for (unsigned int i = 0; i < n; ++i) {
      out.push_back(kHex[md[i] >> 4]);
      out.push_back(kHex[md[i] & 15]);
    }
    return out;
  }
};

class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }
  int release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

void write_all(int fd, const std::uint8_t* data, std::size_t n, const fs::path& path) {
  while (n > 0) {
    ssize_t w = ::write(fd, data, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      throw io_failure("cannot write " + path.string(), errno);
    }
    data += w;
    n -= static_cast<std::size_t>(w);
  }
}

// A directory's entries (a rename, a new subdirectory) are durable only once the directory is synced.
void fsync_dir(const fs::path& dir) {
  Fd fd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (fd.get() < 0) throw io_failure("cannot open directory " + dir.string(), errno);
  if (::fsync(fd.get()) != 0) throw io_failure("cannot sync directory " + dir.string(), errno);
}

void ensure_dir(const fs::path& dir) {
  if (::mkdir(dir.c_str(), 0755) == 0) {
    fsync_dir(dir.parent_path());
  } else if (errno != EEXIST) {
    throw io_failure("cannot create " + dir.string(), errno);
  }
}

fs::path temp_name(const fs::path& dir) {
  static std::atomic<std::uint64_t> counter{0};
  return dir / (std::string(kTempPrefix) + std::to_string(::getpid()) + "-" + std::to_string(counter++));
}

bool is_hex(std::string_view s) {
  for (char c : s) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

}  // namespace

BlobStore::BlobStore(fs::path root) : root_(std::move(root)) {
  std::error_code ec;
  fs::create_directories(root_, ec);
  if (ec) throw Error(ErrorClass::io_error, "cannot create the blob store " + root_.string() + ": " + ec.message());
}

bool BlobStore::is_sha256(std::string_view s) { return s.size() == 64 && is_hex(s); }

fs::path BlobStore::path_of(std::string_view sha256) const {
  if (!is_sha256(sha256)) {
    throw Error(ErrorClass::bad_parameter, "'" + std::string(sha256.substr(0, 80)) + "' is not a SHA-256",
                "a blob is named by the 64 lower-case hex digits of its SHA-256");
  }
  return root_ / std::string(sha256.substr(0, 2)) / std::string(sha256.substr(2));
}

void BlobStore::publish(const fs::path& tmp, const std::string& sha256) const {
  const fs::path final_path = path_of(sha256);
  if (::rename(tmp.c_str(), final_path.c_str()) != 0) {
    int err = errno;
    ::unlink(tmp.c_str());
    throw io_failure("cannot rename into " + final_path.string(), err);
  }
  fsync_dir(final_path.parent_path());
}

std::string BlobStore::put(std::span<const std::uint8_t> bytes) {
  Digest d;
  d.update(bytes.data(), bytes.size());
  const std::string sha = d.hex();
  const fs::path final_path = path_of(sha);
  std::error_code ec;
  // The same bytes again (a preview rendered twice, identical frames): the stored file is theirs.
  if (fs::exists(final_path, ec) && fs::file_size(final_path, ec) == bytes.size() && !ec) return sha;
  ensure_dir(final_path.parent_path());
  const fs::path tmp = temp_name(final_path.parent_path());
  {
    Fd fd(::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644));
    if (fd.get() < 0) throw io_failure("cannot create " + tmp.string(), errno);
    try {
      write_all(fd.get(), bytes.data(), bytes.size(), tmp);
      if (::fsync(fd.get()) != 0) throw io_failure("cannot sync " + tmp.string(), errno);
    } catch (...) {
      ::unlink(tmp.c_str());
      throw;
    }
  }
  publish(tmp, sha);
  return sha;
}

std::string BlobStore::put_file(const fs::path& source) {
  // Hashed first, then copied under its name: the copy lands in its final directory, so one
  // directory sync makes it durable. The second read comes from the page cache.
  const std::string sha = hash_file(source);
  const fs::path final_path = path_of(sha);
  std::error_code ec;
  const auto size = fs::file_size(source, ec);
  if (ec) throw Error(ErrorClass::io_error, "cannot read " + source.string() + ": " + ec.message());
  if (fs::exists(final_path, ec) && fs::file_size(final_path, ec) == size && !ec) return sha;
  ensure_dir(final_path.parent_path());
  const fs::path tmp = temp_name(final_path.parent_path());
  {
    Fd in(::open(source.c_str(), O_RDONLY | O_CLOEXEC));
    if (in.get() < 0) throw io_failure("cannot open " + source.string(), errno);
    Fd out(::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644));
    if (out.get() < 0) throw io_failure("cannot create " + tmp.string(), errno);
    try {
      Digest check;
      std::vector<std::uint8_t> buf(kChunk);
      for (;;) {
        ssize_t n = ::read(in.get(), buf.data(), buf.size());
        if (n < 0) {
          if (errno == EINTR) continue;
          throw io_failure("cannot read " + source.string(), errno);
        }
        if (n == 0) break;
        check.update(buf.data(), static_cast<std::size_t>(n));
        write_all(out.get(), buf.data(), static_cast<std::size_t>(n), tmp);
      }
      // The source changed between the two reads (a camera still writing it): not these bytes.
      if (check.hex() != sha) {
        throw Error(ErrorClass::io_error, source.string() + " changed while it was being stored", "store it again once it is complete");
      }
      if (::fsync(out.get()) != 0) throw io_failure("cannot sync " + tmp.string(), errno);
    } catch (...) {
      ::unlink(tmp.c_str());
      throw;
    }
  }
  publish(tmp, sha);
  return sha;
}

std::string BlobStore::hash_file(const fs::path& file) {
  Fd in(::open(file.c_str(), O_RDONLY | O_CLOEXEC));
  if (in.get() < 0) throw io_failure("cannot open " + file.string(), errno);
  Digest d;
  std::vector<std::uint8_t> buf(kChunk);
  for (;;) {
    ssize_t n = ::read(in.get(), buf.data(), buf.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      throw io_failure("cannot read " + file.string(), errno);
    }
    if (n == 0) break;
    d.update(buf.data(), static_cast<std::size_t>(n));
  }
  return d.hex();
}

BlobScan BlobStore::scan() const {
  BlobScan out;
  std::error_code ec;
  // A temporary file of this very process is a write in progress (the check runs while frames are being kept),
  // not a partial one: only another process's — a colorlabd that died mid-write — is left over.
  const std::string own_temp = std::string(kTempPrefix) + std::to_string(::getpid()) + "-";
  for (const auto& top : fs::directory_iterator(root_, ec)) {
    const std::string dir = top.path().filename().string();
    if (!top.is_directory() || dir.size() != 2 || !is_hex(dir)) {
      out.strays.push_back({top.path(), "not a blob name"});
      continue;
    }
    for (const auto& f : fs::directory_iterator(top.path(), ec)) {
      const std::string name = f.path().filename().string();
      if (name.rfind(own_temp, 0) == 0) {
        continue;
      } else if (name.rfind(kTempPrefix, 0) == 0) {
        out.strays.push_back({f.path(), "partial write"});
      } else if (f.is_regular_file() && name.size() == 62 && is_hex(name)) {
        std::error_code size_ec;
        out.files.push_back({dir + name, static_cast<std::uint64_t>(f.file_size(size_ec))});
      } else {
        out.strays.push_back({f.path(), "not a blob name"});
      }
    }
  }
  if (ec) throw Error(ErrorClass::io_error, "cannot list the blob store " + root_.string() + ": " + ec.message());
  return out;
}

bool BlobStore::remove(std::string_view sha256) const {
  const fs::path p = path_of(sha256);
  if (::unlink(p.c_str()) != 0) {
    if (errno == ENOENT) return false;
    throw io_failure("cannot remove " + p.string(), errno);
  }
  fsync_dir(p.parent_path());
  return true;
}

}  // namespace colorlab::store
