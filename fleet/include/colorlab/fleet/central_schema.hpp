#pragma once
// The central catalog's schema in PostgreSQL, versioned by the rows of schema_migrations (one per applied
// migration). Many benches share it, so only an empty database is set up implicitly; an existing older schema is
// upgraded by `colorlab-ship central-init`, run once by whoever looks after the central server.
#include "colorlab/fleet/pg.hpp"

namespace colorlab::fleet {

// The schema version this build writes.
inline constexpr int kCentralSchemaVersion = 2;

// 0 when the database holds no colorlab schema.
int central_schema_version(Pg& pg);
// Applies every missing migration, each in its own transaction; an advisory lock serialises concurrent callers.
// Error{conflict} when the database is newer than this build.
void central_migrate(Pg& pg);
// For the agent: sets up an empty database, otherwise refuses (Error{conflict}, saying what to upgrade) unless
// the schema is exactly kCentralSchemaVersion.
void central_require(Pg& pg);

}  // namespace colorlab::fleet
