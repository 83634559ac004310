#include "colorlab/daemon/read_connections.hpp"

#include <atomic>
#include <memory>
#include <unordered_map>

namespace colorlab::daemon {

namespace {
std::atomic<std::uint64_t> next_generation{1};
}

ReadConnections::ReadConnections(std::filesystem::path database)
    : database_(std::move(database)), generation_(next_generation++) {}

store::Store& ReadConnections::for_this_thread() {
  thread_local std::unordered_map<std::uint64_t, std::unique_ptr<store::Store>> connections;
  auto& c = connections[generation_];
  if (!c) c = std::make_unique<store::Store>(database_, store::Store::ReadOnly{});
  return *c;
}

}  // namespace colorlab::daemon
