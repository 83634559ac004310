#include "colorlab/protocol/problem.hpp"

#include <utility>

namespace colorlab::protocol {

std::string_view to_string(ProblemCategory c) {
  switch (c) {
    case ProblemCategory::validation: return "validation";
    case ProblemCategory::defined_execution: return "defined_execution";
    case ProblemCategory::undefined_execution: return "undefined_execution";
    case ProblemCategory::framework: return "framework";
    case ProblemCategory::connection: return "connection";
  }
  return "framework";
}

nlohmann::json Problem::to_json() const {
  nlohmann::json j{{"type", "https://colorlab.invalid/problems/" + code},
                   {"title", title},
                   {"status", status},
                   {"detail", detail},
                   {"category", to_string(category)},
                   {"code", code}};
  if (!hint.empty()) j["hint"] = hint;
  if (!instance.empty()) j["instance"] = instance;
  return j;
}

Problem Problem::from_json(const nlohmann::json& j) {
  Problem p;
  p.status = j.value("status", 500);
  p.code = j.value("code", std::string("unknown"));
  p.title = j.value("title", std::string());
  p.detail = j.value("detail", std::string());
  p.hint = j.value("hint", std::string());
  p.instance = j.value("instance", std::string());
  return p;
}

ProblemCategory category_for_status(int status) {
  if (status < 500) return ProblemCategory::validation;
  if (status == 500) return ProblemCategory::undefined_execution;
  if (status == 502 || status == 504) return ProblemCategory::connection;
  return ProblemCategory::framework;
}

Problem problem_for_status(int status, std::string code, std::string title, std::string detail, std::string hint) {
  Problem p;
  p.status = status;
  p.code = std::move(code);
  p.title = std::move(title);
  p.detail = std::move(detail);
  p.hint = std::move(hint);
  p.category = category_for_status(status);
  return p;
}

Problem problem_from_error(const Error& e) {
  Problem p;
  p.detail = e.info().message;
  p.hint = e.hint();
  p.code = std::string(to_string(e.cls()));
  switch (e.cls()) {
    case ErrorClass::bad_parameter:
    case ErrorClass::bad_data:
      p.status = 400;
      p.category = ProblemCategory::validation;
      p.title = "Invalid request";
      break;
    case ErrorClass::not_found:
      p.status = 404;
      p.category = ProblemCategory::validation;
      p.title = "Not found";
      break;
    case ErrorClass::conflict:
      p.status = 409;
      p.category = ProblemCategory::validation;
      p.title = "Conflict";
      break;
    case ErrorClass::io_error:
      p.status = 503;
      p.category = ProblemCategory::undefined_execution;
      p.title = "Storage failure";
      break;
    case ErrorClass::script_error:
      p.status = 422;
      p.category = ProblemCategory::defined_execution;
      p.title = "Campaign script failed";
      break;
    case ErrorClass::aborted:
      p.status = 409;
      p.category = ProblemCategory::defined_execution;
      p.title = "Aborted";
      break;
    case ErrorClass::internal:
      p.status = 500;
      p.category = ProblemCategory::undefined_execution;
      p.title = "Internal error";
      break;
    case ErrorClass::no_comms:
    case ErrorClass::timeout:
    case ErrorClass::coms_fail:
      p.status = 502;
      p.category = ProblemCategory::connection;
      p.title = "Instrument communication failed";
      break;
    default:
      p.status = 502;
      p.category = ProblemCategory::defined_execution;
      p.title = "Instrument error";
      break;
  }
  return p;
}

}  // namespace colorlab::protocol
