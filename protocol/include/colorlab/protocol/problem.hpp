#pragma once
// RFC 9457 problem details with SiLA's error categories, so a client can tell a bad request
// (validation) from an instrument failure (defined_execution) without parsing prose.
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"

namespace colorlab::protocol {

enum class ProblemCategory {
  validation,
  defined_execution,
  undefined_execution,
  framework,
  connection
};
std::string_view to_string(ProblemCategory c);

struct Problem {
  int status = 500;
  std::string code;  // stable, documented: "not-found", "bad-json", ...
  std::string title;
  std::string detail;
  ProblemCategory category = ProblemCategory::framework;
  std::string hint;
  std::string instance;

  nlohmann::json to_json() const;  // {type, title, status, detail, instance, category, code, hint}
  static Problem from_json(const nlohmann::json& j);
};

// The HTTP status and category a colorlab::Error maps to.
Problem problem_from_error(const Error& e);

// The category of a problem answered by status alone (no colorlab::Error in hand), agreeing with
// problem_from_error: 4xx validation (the request), 500 undefined_execution (the server failed),
// 502 and 504 connection (something behind the server), any other 5xx framework (the server cannot
// take the request now: 503 busy, too many connections).
ProblemCategory category_for_status(int status);

// A problem answered by status alone, its category from category_for_status: the one way the HTTP
// server and the API build such an answer.
Problem problem_for_status(int status, std::string code, std::string title, std::string detail, std::string hint);

}  // namespace colorlab::protocol
