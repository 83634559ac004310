#pragma once
// Each thread that serves stored data reads through its own read-only SQLite connection: WAL
// readers never wait for the writer's fsync, and SQLite connections are not shared across threads.
#include <cstdint>
#include <filesystem>

#include "colorlab/store/store.hpp"

namespace colorlab::daemon {

class ReadConnections {
 public:
  explicit ReadConnections(std::filesystem::path database);
  // The calling thread's connection to this database, opened on first use.
  store::Store& for_this_thread();

 private:
  std::filesystem::path database_;
  std::uint64_t generation_;  // tells apart successive instances at one address (tests run several daemons)
};

}  // namespace colorlab::daemon
