#pragma once
// What a caller may do, ordered read < control < admin (docs/API.md, "Access"). Each route's row in
// the route table names the scope it needs; access.hpp grants scopes to callers.
#include <optional>
#include <string_view>

namespace colorlab::daemon {

enum class Scope {
  read = 0,
  control = 1,
  admin = 2
};
std::string_view to_string(Scope s);
std::optional<Scope> scope_from_string(std::string_view s);

}  // namespace colorlab::daemon
