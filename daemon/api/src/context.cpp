#include "colorlab/api/context.hpp"

#include "colorlab/daemon/read_connections.hpp"

namespace colorlab::daemon {

// Without read connections (a context built by hand) the writer serves the reads too.
store::Store& ApiContext::reads() { return readers ? readers->for_this_thread() : store; }

}  // namespace colorlab::daemon
