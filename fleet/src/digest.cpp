#include "colorlab/fleet/digest.hpp"

#include <openssl/evp.h>

#include <bit>
#include <cstring>
#include <string>

namespace colorlab::fleet {

namespace {
// One expression over the run row `r`, shared by the one-run and the many-runs statements.
const std::string kDigestOfRun = R"sql(
encode(sha256(
  convert_to(concat_ws(E'\x1f', r.id, r.status, coalesce(r.finished_at, '\N'), coalesce(r.summary, '\N'),
                       coalesce(r.error, '\N'), r.params) || E'\n', 'UTF8')
  || coalesce((SELECT string_agg(int8send(m.seq)
                  || convert_to(concat_ws(E'\x1f', m.step, m.instrument_id, m.simulated::text, m.quantity,
                                          coalesce(m.unit, '\N'), coalesce(m.data, '\N'), m.measured_at), 'UTF8')
                  || CASE WHEN m.value IS NULL THEN '\x00'::bytea ELSE '\x01'::bytea || float8send(m.value) END,
                  ''::bytea ORDER BY m.seq, m.step COLLATE "C")
               FROM measurements m WHERE m.run_id = r.id), ''::bytea)
  || coalesce((SELECT string_agg(convert_to(concat_ws(E'\x1f', b.name, b.sha256, b.kind, b.step) || E'\n', 'UTF8'),
                  ''::bytea ORDER BY b.name COLLATE "C")
               FROM run_blobs b WHERE b.run_id = r.id), ''::bytea)), 'hex')
)sql";
const std::string kOne = "SELECT " + kDigestOfRun + " FROM runs r WHERE r.id = $1";
const std::string kMany = "SELECT r.id, " + kDigestOfRun + " FROM runs r WHERE r.id = ANY($1::text[])";
}  // namespace

const char* const kCentralDigestSql = kOne.c_str();
const char* const kCentralDigestsSql = kMany.c_str();

namespace {

constexpr char kSep = '\x1f';
const std::string kNull = "\\N";

void big_endian(std::string& out, std::uint64_t v) {
  for (int i = 7; i >= 0; --i) out += static_cast<char>((v >> (8 * i)) & 0xff);
}

}  // namespace

struct RunDigest::Impl {
  EVP_MD_CTX* ctx = EVP_MD_CTX_new();
};

RunDigest::RunDigest() : impl_(new Impl) { EVP_DigestInit_ex(impl_->ctx, EVP_sha256(), nullptr); }

RunDigest::~RunDigest() {
  EVP_MD_CTX_free(impl_->ctx);
  delete impl_;
}

void RunDigest::add(const std::string& bytes) { EVP_DigestUpdate(impl_->ctx, bytes.data(), bytes.size()); }

void RunDigest::run(const std::string& id, const std::string& status, const std::optional<std::string>& finished_at,
                    const std::optional<std::string>& summary, const std::optional<std::string>& error,
                    const std::string& params) {
  add(id + kSep + status + kSep + finished_at.value_or(kNull) + kSep + summary.value_or(kNull) + kSep +
      error.value_or(kNull) + kSep + params + "\n");
}

void RunDigest::measurement(std::int64_t seq, const std::string& step, const std::string& instrument_id,
                            std::int64_t simulated, const std::string& quantity, const std::optional<std::string>& unit,
                            const std::optional<std::string>& data, const std::string& measured_at,
                            std::optional<double> value) {
  std::string b;
  big_endian(b, static_cast<std::uint64_t>(seq));
  b += step + kSep + instrument_id + kSep + std::to_string(simulated) + kSep + quantity + kSep + unit.value_or(kNull) +
       kSep + data.value_or(kNull) + kSep + measured_at;
  if (value) {
    b += '\x01';
    big_endian(b, std::bit_cast<std::uint64_t>(*value));
  } else {
    b += '\x00';
  }
  add(b);
}

void RunDigest::blob_ref(const std::string& name, const std::string& sha256, const std::string& kind,
                         const std::string& step) {
  add(name + kSep + sha256 + kSep + kind + kSep + step + "\n");
}

std::string RunDigest::hex() {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  EVP_DigestFinal_ex(impl_->ctx, md, &len);
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (unsigned i = 0; i < len; ++i) {
    out += digits[md[i] >> 4];
    out += digits[md[i] & 15];
  }
  return out;
}

}  // namespace colorlab::fleet
