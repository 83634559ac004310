#pragma once
// A thin RAII layer over libpq: every failure becomes colorlab::Error{no_comms} for a lost or refused
// connection, io_error for anything the server refused, with the server's own message.
#include <optional>
#include <string>
#include <vector>

struct pg_conn;
struct pg_result;

namespace colorlab::fleet {

class PgResult {
 public:
  explicit PgResult(pg_result* r) : r_(r) {}
  ~PgResult();
  PgResult(PgResult&& o) noexcept : r_(o.r_) { o.r_ = nullptr; }
  PgResult(const PgResult&) = delete;
  int rows() const;
  bool is_null(int row, int col) const;
  std::string text(int row, int col) const;
  long long int64(int row, int col) const;

 private:
  pg_result* r_;
};

class Pg {
 public:
  // Error{no_comms} with libpq's message when the server cannot be reached or refuses the login.
  explicit Pg(const std::string& conninfo);
  ~Pg();
  Pg(const Pg&) = delete;
  Pg& operator=(const Pg&) = delete;

  // Whether the connection is still up (a pool drops one that is not).
  bool ok() const;
  void exec(const std::string& sql);
  // $1.. parameters as text; std::nullopt is NULL.
  PgResult query(const std::string& sql, const std::vector<std::optional<std::string>>& params = {});
  // COPY <table> FROM STDIN in text format; `data` holds whole lines (copy_field() escapes a value).
  void copy_in(const std::string& table, const std::string& data);
  // The same, the lines given in pieces (several runs' rows in one COPY, without joining them first).
  void copy_in(const std::string& table, const std::vector<const std::string*>& pieces);

 private:
  [[noreturn]] void fail(const std::string& what, pg_result* r = nullptr);
  pg_conn* c_ = nullptr;
};

// One value of a COPY text line: backslash, tab, newline and carriage return escaped; nullopt is \N.
void copy_field(std::string& line, const std::optional<std::string>& v, bool last = false);

}  // namespace colorlab::fleet
