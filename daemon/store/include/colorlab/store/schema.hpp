#pragma once
// Forward-only schema migrations keyed by PRAGMA user_version. A database written by a newer
// colorlab is refused rather than misread.
#include "colorlab/store/sqlite.hpp"

namespace colorlab::store {

inline constexpr int kSchemaVersion = 8;
// 'CLAB' — marks the file as colorlab's (PRAGMA application_id).
inline constexpr int kApplicationId = 0x434c4142;

// Applies every migration above the file's user_version, each in its own transaction.
// Throws Error{io_error} for a newer or foreign database.
void migrate(Database& db);
int schema_version(Database& db);

}  // namespace colorlab::store
