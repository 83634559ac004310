// A POST /v1/executions body into validated campaign parameters: the body's JSON and shape checked as
// api.cpp's post_execution checks them, then the campaign looked up in the catalogue of the shipped
// scripts (re-read as on every request) and its `params` validated against the script's declaration —
// the steps of validate_campaign_params (daemon/core campaign_request.cpp, whose file also holds the
// live lab's instrument check and so is not linked here).
#include <nlohmann/json.hpp>

#include "colorlab/campaigns/catalogue.hpp"
#include "fuzz_support.hpp"

namespace {

using colorlab::fuzz::typed;
using nlohmann::json;

colorlab::campaigns::ScriptCatalogue& catalogue() {
  static colorlab::campaigns::ScriptCatalogue shipped(
      {{std::filesystem::path(COLORLAB_SOURCE_DIR) / "campaigns" / "scripts", "shipped"}});
  return shipped;
}

void one_input(const std::uint8_t* data, std::size_t size) {
  json body = json::parse(colorlab::fuzz::as_text(data, size), nullptr, false);
  if (body.is_discarded() || !body.is_object() || !body.contains("campaign") || !body["campaign"].is_string()) return;
  json params = body.value("params", json::object());
  auto& scripts = catalogue();
  typed("validate_campaign_params", [&] {
    scripts.refresh();
    auto script = scripts.find(body["campaign"].get<std::string>());
    if (!script) return;
    json valid = script->validate(params);
    // What the engine receives: every declared parameter, nothing else.
    for (const auto& [key, spec] : script->parameters.items()) {
      if (!valid.contains(key)) {
        std::fprintf(stderr, "fuzz: validated params lack '%s'\n", key.c_str());
        std::abort();
      }
    }
    if (valid.size() != script->parameters.size()) {
      std::fprintf(stderr, "fuzz: validated params hold undeclared keys: %s\n", valid.dump().c_str());
      std::abort();
    }
  });
}

}  // namespace

COLORLAB_FUZZ_TARGET("campaign_params", one_input)
