#pragma once
// What a client or the daemon asks of a running execution. The engine looks at it at every safe
// point (between two lab calls, after the step before is committed) and inside long waits.
#include <string>

namespace colorlab::campaigns {

struct ExecutionControl {
  enum class Request {
    none,
    pause,
    abort,
    shutdown
  };
  Request request = Request::none;
  std::string reason;
  std::string execution_id;  // whose calls these are (operator requests name it)
  bool requested() const { return request != Request::none; }
};

}  // namespace colorlab::campaigns
