#include "access_commands.hpp"

#include <memory>
#include <sstream>

#include "client_support.hpp"

namespace colorlab::cli {

using nlohmann::json;

namespace {

std::string text_or(const json& j, const char* key, const std::string& fallback) {
  return j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : fallback;
}

std::string format_created_key(const json& k) {
  std::ostringstream out;
  out << "created API key '" << text_or(k, "name", "?") << "' with scope " << text_or(k, "scope", "?") << " (id "
      << text_or(k, "id", "?") << ")\n"
      << "the key, shown only now (colorlabd keeps only its hash):\n"
      << text_or(k, "secret", "?") << "\n"
      << "use it with: colorlab --key KEY … or COLORLAB_API_KEY=KEY\n";
  return out.str();
}

std::string format_key(const json& k) {
  std::ostringstream out;
  out << text_or(k, "id", "?") << "  " << text_or(k, "scope", "?") << "  " << text_or(k, "name", "?")
      << "  created " << text_or(k, "created_at", "?") << ", last used " << text_or(k, "last_used_at", "never");
  if (k.value("revoked", false)) out << ", REVOKED " << text_or(k, "revoked_at", "");
  out << "\n";
  return out.str();
}

std::string format_keys(const json& list) {
  if (list["items"].empty()) return "no API keys (colorlab keys create NAME --scope read|control|admin)\n";
  std::string out;
  for (const auto& k : list["items"]) out += format_key(k);
  return out;
}

std::string format_control(const json& s) {
  std::ostringstream out;
  if (!s.value("held", false)) {
    out << "the control lock is free";
  } else {
    out << "the control lock is held by '" << text_or(s, "holder", "?") << "' since " << text_or(s, "since", "?")
        << " (until " << text_or(s, "expires_at", "?") << " unless renewed)";
    if (s.value("yours", false)) out << " — that is you";
  }
  out << "\n";
  return out.str();
}

struct CreateOptions {
  std::string name;
  std::string scope = "read";
};

struct AcquireOptions {
  std::string holder;
  bool force = false;
};

}  // namespace

void add_access_commands(CLI::App& app, GlobalOptions& global) {
  auto* keys = app.add_subcommand("keys", "API keys for clients beyond the Unix socket (needs the admin scope)");
  keys->require_subcommand(1);

  auto create_opts = std::make_shared<CreateOptions>();
  auto* create = keys->add_subcommand("create", "Create a key; it is printed once and stored only as a hash");
  create->add_option("name", create_opts->name, "who or what holds it, e.g. alice-laptop")->required();
  create->add_option("--scope", create_opts->scope, "read: GETs; control: also drive the lab; admin: also keys")
      ->check(CLI::IsMember({"read", "control", "admin"}))
      ->capture_default_str();
  create->callback([&global, create_opts] {
    print(global, make_client(global).post("/v1/keys", {{"name", create_opts->name}, {"scope", create_opts->scope}}),
          format_created_key);
  });

  auto* list = keys->add_subcommand("list", "List the keys (never their secrets), revoked ones included");
  list->callback([&global] { print(global, make_client(global).get("/v1/keys"), format_keys); });

  auto revoke_id = std::make_shared<std::string>();
  auto* revoke = keys->add_subcommand("revoke", "Revoke a key: its requests get 401 from now on");
  revoke->add_option("id", *revoke_id, "key id (from colorlab keys list)")->required();
  revoke->callback([&global, revoke_id] { print(global, make_client(global).del("/v1/keys/" + *revoke_id), format_key); });

  auto* control = app.add_subcommand("control", "The control lock: one client drives the instruments at a time");
  control->require_subcommand(1);

  auto acquire_opts = std::make_shared<AcquireOptions>();
  auto* acquire = control->add_subcommand("acquire", "Take the control lock (or renew it); others get 409 meanwhile");
  acquire->add_option("--holder", acquire_opts->holder, "the name others are shown (default: the key's name, or local)");
  acquire->add_flag("--force", acquire_opts->force, "take it from its holder (Unix socket or admin key)");
  acquire->callback([&global, acquire_opts] {
    json body = json::object();
    if (!acquire_opts->holder.empty()) body["holder"] = acquire_opts->holder;
    if (acquire_opts->force) body["force"] = true;
    print(global, make_client(global).post("/v1/control/acquire", body), format_control);
  });

  auto release_force = std::make_shared<bool>(false);
  auto* release = control->add_subcommand("release", "Give the control lock up");
  release->add_flag("--force", *release_force, "release another client's lock (Unix socket or admin key)");
  release->callback([&global, release_force] {
    json body = json::object();
    if (*release_force) body["force"] = true;
    print(global, make_client(global).post("/v1/control/release", body), format_control);
  });

  auto* status = control->add_subcommand("status", "Who holds the control lock, since when");
  status->callback([&global] { print(global, make_client(global).get("/v1/control"), format_control); });
}

}  // namespace colorlab::cli
