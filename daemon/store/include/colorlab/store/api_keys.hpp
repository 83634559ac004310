#pragma once
// API keys as stored: only the SHA-256 of each key is kept, so a copy of the database (a backup, a
// bug report) hands out no access. The key itself is shown once, when it is created. Creating and
// revoking are each one transaction with an `access` event (never the secret) for the audit trail.
#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/store/store.hpp"

namespace colorlab::store {

struct ApiKeyRecord {
  std::string id;  // UUIDv7: names the key in lists, events and logs; not secret
  std::string name;
  std::string scope;  // read | control | admin
  std::string created_at;
  std::optional<std::string> last_used_at;
  std::optional<std::string> revoked_at;
  nlohmann::json to_json() const;  // never holds the secret or its hash
};

// What a request's key is checked against: the key cache keeps these by secret hash.
struct ApiKeyEntry {
  std::string id;
  std::string name;
  std::string scope;
  bool revoked = false;
};

// "clk_" + 32 random bytes (OpenSSL's CSPRNG) as unpadded base64url: 256 bits, so a hash lookup
// is as good as a constant-time comparison (nobody finds a preimage).
std::string generate_api_key();
// Lower-case hex SHA-256 of the whole key, as stored in api_keys.secret_sha256.
std::string api_key_sha256(const std::string& key);

class ApiKeyStore {
 public:
  // Any Store: the writer for changes, a reader's connection for list() and entries().
  explicit ApiKeyStore(Store& store) : store_(store) {}

  struct Created {
    ApiKeyRecord key;
    std::string secret;  // the only time it exists outside the client
  };
  // Error{bad_parameter} for an empty or over-long name or an unknown scope.
  Created create(const std::string& name, const std::string& scope);
  // Oldest first, revoked ones included (they say when they were revoked).
  std::vector<ApiKeyRecord> list();
  std::optional<ApiKeyRecord> find(const std::string& id);
  // Error{not_found} for an unknown id; revoking a revoked key changes nothing and returns it.
  ApiKeyRecord revoke(const std::string& id);
  // Every key by secret hash, for the in-memory cache.
  std::map<std::string, ApiKeyEntry> entries();
  // Records when keys were last used (id → ISO time), all in one transaction.
  void touch(const std::map<std::string, std::string>& last_used);

 private:
  Store& store_;
};

}  // namespace colorlab::store
