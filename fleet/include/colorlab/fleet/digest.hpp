#pragma once
// The per-run digest both sides compute: SHA-256 over the run's identifying row, its measurements (ordered by
// seq, then step) and its blob references (ordered by name, bytewise). Doubles enter as their 8 IEEE bytes and
// integers big-endian, the way PostgreSQL's float8send/int8send give them, so the bench (C++ over SQLite) and
// central (one SQL statement, kCentralDigestSql) hash identical bytes. ON CONFLICT DO NOTHING would accept a
// different row under an existing id; comparing digests is what notices.
#include <cstdint>
#include <optional>
#include <string>

namespace colorlab::fleet {

// $1 = run id; one row, one column: the hex digest (no row when central lacks the run).
extern const char* const kCentralDigestSql;
// $1 = a text[] of run ids ('{id,id}'); a row (id, hex digest) for each run central holds. One statement for a
// transaction of several runs: one round trip instead of one a run.
extern const char* const kCentralDigestsSql;

class RunDigest {
 public:
  RunDigest();
  ~RunDigest();
  RunDigest(const RunDigest&) = delete;
  RunDigest& operator=(const RunDigest&) = delete;

  void run(const std::string& id, const std::string& status, const std::optional<std::string>& finished_at,
           const std::optional<std::string>& summary, const std::optional<std::string>& error, const std::string& params);
  // In seq order (then step, bytewise).
  void measurement(std::int64_t seq, const std::string& step, const std::string& instrument_id, std::int64_t simulated,
                   const std::string& quantity, const std::optional<std::string>& unit,
                   const std::optional<std::string>& data, const std::string& measured_at, std::optional<double> value);
  // In name order, bytewise.
  void blob_ref(const std::string& name, const std::string& sha256, const std::string& kind, const std::string& step);
  std::string hex();

 private:
  void add(const std::string& bytes);
  struct Impl;
  Impl* impl_;
};

}  // namespace colorlab::fleet
