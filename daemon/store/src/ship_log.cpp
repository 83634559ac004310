#include "colorlab/store/ship_log.hpp"

namespace colorlab::store {

ShipBacklog ShipLog::backlog(std::int64_t position) {
  ReadTransaction tx(db_);
  ShipBacklog b;
  {
    // seq is the key: only the log after the position is read, which is short while the agent keeps up.
    auto st = db_.prepare("SELECT count(*) FROM event_log WHERE seq > ?1 AND " + kEndEventSql);
    st.bind(1, position);
    if (st.step()) b.runs = st.int64(0);
  }
  if (b.runs > 0) {
    auto st = db_.prepare(
        "SELECT r.id, r.status, r.finished_at FROM event_log e JOIN runs r ON r.id = json_extract(e.payload, '$.run_id') "
        "WHERE e.seq > ?1 AND " +
        kEndEventSql + " ORDER BY e.seq LIMIT 1");
    st.bind(1, position);
    if (st.step()) {
      b.oldest_run_id = st.text(0);
      b.oldest_status = st.text(1);
      if (!st.is_null(2)) b.oldest_ended_at = st.text(2);
    }
  }
  auto last = db_.prepare("SELECT coalesce(max(seq), 0) FROM event_log");
  if (last.step()) b.last_event = last.int64(0);
  return b;
}

int record_missing_end_events(Database& db, const std::string& now) {
  // One pass over the log for the runs that have an end event; an execution id when the run has one, so the
  // event reads like the others.
  db.prepare(std::string(
                 "INSERT INTO event_log (time, topic, payload) "
                 "SELECT ?1, 'execution', json_object('execution_id', (SELECT e.id FROM executions e WHERE e.run_id = r.id "
                 "ORDER BY e.created_at DESC LIMIT 1), 'run_id', r.id, 'status', r.status, 'reason', "
                 "'ended before this colorlabd started; recorded at start-up so that it ships', 'recorded_at_open', "
                 "json('true')) FROM runs r WHERE r.status IN ") +
             kEndedStatusesSql + " AND r.id NOT IN (SELECT json_extract(payload, '$.run_id') FROM event_log WHERE " +
             kEndEventSql + ") ORDER BY r.seq")
      .bind(1, std::string_view(now))
      .run();
  return db.changes();
}

}  // namespace colorlab::store
