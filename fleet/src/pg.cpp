#include "colorlab/fleet/pg.hpp"

#include <libpq-fe.h>

#include "colorlab/core/error.hpp"

namespace colorlab::fleet {

PgResult::~PgResult() {
  if (r_) PQclear(r_);
}
int PgResult::rows() const { return PQntuples(r_); }
bool PgResult::is_null(int row, int col) const { return PQgetisnull(r_, row, col) != 0; }
std::string PgResult::text(int row, int col) const { return PQgetvalue(r_, row, col); }
long long PgResult::int64(int row, int col) const { return std::stoll(PQgetvalue(r_, row, col)); }

namespace {
// Server notices ("relation already exists, skipping") are expected in idempotent set-up, not news for stderr.
void quiet_notices(void*, const char*) {}
}  // namespace

Pg::Pg(const std::string& conninfo) {
  c_ = PQconnectdb(conninfo.c_str());
  if (c_) PQsetNoticeProcessor(c_, quiet_notices, nullptr);
  if (PQstatus(c_) != CONNECTION_OK) {
    // libpq's message names host, port and cause; the conninfo itself is never repeated (it may hold secrets).
    std::string msg = c_ ? PQerrorMessage(c_) : "out of memory";
    while (!msg.empty() && msg.back() == '\n') msg.pop_back();
    PQfinish(c_);
    c_ = nullptr;
    throw Error(ErrorClass::no_comms, "cannot connect to the central PostgreSQL: " + msg,
                "check [ship] postgres (host, port, dbname, user, sslmode) and that the server runs");
  }
}

Pg::~Pg() {
  if (c_) PQfinish(c_);
}

void Pg::fail(const std::string& what, pg_result* r) {
  std::string msg = r ? PQresultErrorMessage(r) : PQerrorMessage(c_);
  if (r) PQclear(r);
  while (!msg.empty() && msg.back() == '\n') msg.pop_back();
  const bool lost = PQstatus(c_) != CONNECTION_OK;
  throw Error(lost ? ErrorClass::no_comms : ErrorClass::io_error, "central PostgreSQL, " + what + ": " + msg,
              lost ? "the connection was lost; the next cycle reconnects" : "");
}

bool Pg::ok() const { return c_ && PQstatus(c_) == CONNECTION_OK; }

void Pg::exec(const std::string& sql) {
  pg_result* r = PQexec(c_, sql.c_str());
  auto st = PQresultStatus(r);
  if (st != PGRES_COMMAND_OK && st != PGRES_TUPLES_OK) fail(sql.substr(0, 60), r);
  PQclear(r);
}

PgResult Pg::query(const std::string& sql, const std::vector<std::optional<std::string>>& params) {
  std::vector<const char*> values;
  values.reserve(params.size());
  for (const auto& p : params) values.push_back(p ? p->c_str() : nullptr);
  pg_result* r = PQexecParams(c_, sql.c_str(), static_cast<int>(values.size()), nullptr, values.data(), nullptr,
                              nullptr, 0);
  auto st = PQresultStatus(r);
  if (st != PGRES_COMMAND_OK && st != PGRES_TUPLES_OK) fail(sql.substr(0, 60), r);
  return PgResult(r);
}

void Pg::copy_in(const std::string& table, const std::string& data) { copy_in(table, {&data}); }

void Pg::copy_in(const std::string& table, const std::vector<const std::string*>& pieces) {
  pg_result* r = PQexec(c_, ("COPY " + table + " FROM STDIN").c_str());
  if (PQresultStatus(r) != PGRES_COPY_IN) fail("COPY " + table, r);
  PQclear(r);
  constexpr std::size_t kChunk = 1 << 20;
  for (const std::string* data : pieces) {
    for (std::size_t off = 0; off < data->size(); off += kChunk) {
      const std::size_t n = std::min(kChunk, data->size() - off);
      if (PQputCopyData(c_, data->data() + off, static_cast<int>(n)) != 1) fail("COPY " + table + " data");
    }
  }
  if (PQputCopyEnd(c_, nullptr) != 1) fail("COPY " + table + " end");
  r = PQgetResult(c_);
  if (PQresultStatus(r) != PGRES_COMMAND_OK) fail("COPY " + table, r);
  PQclear(r);
  while ((r = PQgetResult(c_)) != nullptr) PQclear(r);
}

void copy_field(std::string& line, const std::optional<std::string>& v, bool last) {
  if (!v) {
    line += "\\N";
  } else {
    for (char ch : *v) {
      switch (ch) {
        case '\\': line += "\\\\"; break;
        case '\t': line += "\\t"; break;
        case '\n': line += "\\n"; break;
        case '\r': line += "\\r"; break;
        default: line += ch;
      }
    }
  }
  line += last ? '\n' : '\t';
}

}  // namespace colorlab::fleet
