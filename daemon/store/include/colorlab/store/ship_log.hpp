#pragma once
// The event log as colorlab-ship reads it (fleet/src/bench_reader.cpp): a run ships at the `execution` event that
// ended it. Two jobs on the bench's side: the backlog after the agent's position (what `GET /v1/shipping` shows
// as the lag), and making sure every ended run has such an event, so none is left behind for ever.
#include <cstdint>
#include <string>

#include "colorlab/store/sqlite.hpp"

namespace colorlab::store {

// The statuses that end a run; the same list the agent and blob retention use.
inline constexpr const char* kEndedStatusesSql = "('finished_ok', 'finished_error', 'aborted', 'interrupted')";
// An event_log row that ends a run: where colorlab-ship picks what to ship and the bench counts its backlog.
inline const std::string kEndEventSql = std::string("topic = 'execution' AND json_extract(payload, '$.run_id') IS NOT NULL "
                                                    "AND json_extract(payload, '$.status') IN ") +
                                        kEndedStatusesSql;

// What the bench holds ended but not yet shipped after a position.
struct ShipBacklog {
  std::int64_t runs = 0;
  std::string oldest_run_id;  // empty when runs == 0
  std::string oldest_status;
  std::string oldest_ended_at;  // the oldest run's finished_at (ISO 8601, this bench's clock)
  std::int64_t last_event = 0;  // the newest event on the bench
};

// On a connection of its own (colorlabd's route opens one read-only per request, as the agent does), never inside a
// transaction: it reads in one of its own.
class ShipLog {
 public:
  explicit ShipLog(Database& db) : db_(db) {}

  // Runs ended after event `position` (colorlab-ship's shipped-position note), in one snapshot.
  ShipBacklog backlog(std::int64_t position);

 private:
  Database& db_;
};

// Appends an `execution` event for every ended run that has none (marked `recorded_at_open`), in the caller's
// transaction; returns how many. Runs an older colorlabd finalised at start-up without an event would otherwise
// never ship: the agent only sees runs through their end event.
int record_missing_end_events(Database& db, const std::string& now);

}  // namespace colorlab::store
