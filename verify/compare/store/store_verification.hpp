#pragma once
// Writing a verification into colorlabd's store as a finished run (campaign "verify"), in its own target so the
// comparison engine and its tests do not need SQLite.
#include <string>

#include "colorlab/store/store.hpp"
#include "colorlab/verify/compare/stored.hpp"

namespace colorlab::verify {

// Creates the run and its execution, commits every comparison's row in one step and finishes it `finished_ok`
// (the verification was made; its verdict is in the summary, not in the status). Returns the run id.
std::string store_verification(store::Store& store, const StoredVerification& v);

}  // namespace colorlab::verify
