#include "colorlab/store/api_keys.hpp"

#include <openssl/evp.h>
#include <openssl/rand.h>

#include <array>

#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"

namespace colorlab::store {

namespace {

constexpr std::size_t kMaxNameLength = 100;
constexpr const char* kKeyColumns = "id, name, scope, created_at, last_used_at, revoked_at";

std::string base64url(const unsigned char* data, std::size_t n) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";
  std::string out;
  std::uint32_t bits = 0;
  int count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    bits = (bits << 8) | data[i];
    count += 8;
    while (count >= 6) {
      count -= 6;
      out += kAlphabet[(bits >> count) & 0x3f];
    }
  }
  if (count > 0) out += kAlphabet[(bits << (6 - count)) & 0x3f];
  return out;
}

std::optional<std::string> optional_text(Statement& st, int col) {
  if (st.is_null(col)) return std::nullopt;
  return st.text(col);
}

ApiKeyRecord read_key(Statement& st) {
  return ApiKeyRecord{st.text(0), st.text(1), st.text(2), st.text(3), optional_text(st, 4), optional_text(st, 5)};
}

void check_new_key(const std::string& name, const std::string& scope) {
  if (scope != "read" && scope != "control" && scope != "admin") {
    throw Error(ErrorClass::bad_parameter, "scope must be read, control or admin, not '" + scope + "'",
                "read: GETs only; control: also start, pause and abort executions, the queue, operator answers and "
                "the control lock; admin: also API keys");
  }
  if (name.empty() || name.size() > kMaxNameLength) {
    throw Error(ErrorClass::bad_parameter,
                "a key's name must be 1 to " + std::to_string(kMaxNameLength) + " characters",
                "name it after who holds it, e.g. \"alice-laptop\"");
  }
  for (unsigned char c : name) {
    if (c < 0x20 || c == 0x7f) throw Error(ErrorClass::bad_parameter, "a key's name must not hold control characters");
  }
}

}  // namespace

nlohmann::json ApiKeyRecord::to_json() const {
  auto opt = [](const std::optional<std::string>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); };
  return {{"id", id},
          {"name", name},
          {"scope", scope},
          {"created_at", created_at},
          {"last_used_at", opt(last_used_at)},
          {"revoked_at", opt(revoked_at)},
          {"revoked", revoked_at.has_value()}};
}

std::string generate_api_key() {
  std::array<unsigned char, 32> bytes{};
  if (RAND_bytes(bytes.data(), static_cast<int>(bytes.size())) != 1) {
    throw Error(ErrorClass::internal, "the system's random number generator failed (OpenSSL RAND_bytes)");
  }
  return "clk_" + base64url(bytes.data(), bytes.size());
}

std::string api_key_sha256(const std::string& key) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_Digest(key.data(), key.size(), digest, &length, EVP_sha256(), nullptr) != 1) {
    throw Error(ErrorClass::internal, "SHA-256 failed (OpenSSL EVP_Digest)");
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < length; ++i) {
    out += kHex[digest[i] >> 4];
    out += kHex[digest[i] & 0xf];
  }
  return out;
}

ApiKeyStore::Created ApiKeyStore::create(const std::string& name, const std::string& scope) {
  check_new_key(name, scope);
  Created c;
  c.secret = generate_api_key();
  c.key = ApiKeyRecord{new_uuid_v7(), name, scope, now_iso8601(), std::nullopt, std::nullopt};
  auto& db = store_.db_;
  Transaction tx(db);
  db.prepare("INSERT INTO api_keys (id, name, scope, secret_sha256, created_at) VALUES (?1, ?2, ?3, ?4, ?5)")
      .bind(1, std::string_view(c.key.id))
      .bind(2, std::string_view(c.key.name))
      .bind(3, std::string_view(c.key.scope))
      .bind(4, std::string_view(api_key_sha256(c.secret)))
      .bind(5, std::string_view(c.key.created_at))
      .run();
  store_.append_event("access", {{"event", "key-created"}, {"key", c.key.to_json()}});
  tx.commit();
  return c;
}

std::vector<ApiKeyRecord> ApiKeyStore::list() {
  auto st = store_.db_.prepare(std::string("SELECT ") + kKeyColumns + " FROM api_keys ORDER BY created_at, id");
  std::vector<ApiKeyRecord> out;
  while (st.step()) out.push_back(read_key(st));
  return out;
}

std::optional<ApiKeyRecord> ApiKeyStore::find(const std::string& id) {
  auto st = store_.db_.prepare(std::string("SELECT ") + kKeyColumns + " FROM api_keys WHERE id = ?1");
  st.bind(1, std::string_view(id));
  if (!st.step()) return std::nullopt;
  return read_key(st);
}

ApiKeyRecord ApiKeyStore::revoke(const std::string& id) {
  auto& db = store_.db_;
  Transaction tx(db);
  auto key = find(id);
  if (!key) throw Error(ErrorClass::not_found, "no API key with id '" + id + "'", "colorlab keys list shows the ids");
  if (key->revoked_at) return *key;
  key->revoked_at = now_iso8601();
  db.prepare("UPDATE api_keys SET revoked_at = ?2 WHERE id = ?1")
      .bind(1, std::string_view(id))
      .bind(2, std::string_view(*key->revoked_at))
      .run();
  store_.append_event("access", {{"event", "key-revoked"}, {"key", key->to_json()}});
  tx.commit();
  return *key;
}

std::map<std::string, ApiKeyEntry> ApiKeyStore::entries() {
  auto st = store_.db_.prepare("SELECT secret_sha256, id, name, scope, revoked_at IS NOT NULL FROM api_keys");
  std::map<std::string, ApiKeyEntry> out;
  while (st.step()) out[st.text(0)] = ApiKeyEntry{st.text(1), st.text(2), st.text(3), st.int64(4) != 0};
  return out;
}

void ApiKeyStore::touch(const std::map<std::string, std::string>& last_used) {
  if (last_used.empty()) return;
  auto& db = store_.db_;
  Transaction tx(db);
  auto st = db.prepare("UPDATE api_keys SET last_used_at = ?2 WHERE id = ?1");
  for (const auto& [id, at] : last_used) {
    st.bind(1, std::string_view(id)).bind(2, std::string_view(at));
    st.run();
    st.reset();
  }
  tx.commit();
}

}  // namespace colorlab::store
