#pragma once
// The JSON object a POST to the access routes carries. An empty body is an empty object: the
// control lock's routes take everything as optional.
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/http/message.hpp"

namespace colorlab::daemon {

inline nlohmann::json access_body(const http::HttpRequest& req, const std::string& example) {
  if (req.body.empty()) return nlohmann::json::object();
  auto ct = req.header("content-type").value_or("");
  if (ct.rfind("application/json", 0) != 0) {
    throw Error(ErrorClass::bad_parameter, req.method + " " + req.path + " takes application/json, got '" + ct + "'",
                "e.g. " + example);
  }
  auto body = nlohmann::json::parse(req.body, nullptr, false);
  if (body.is_discarded() || !body.is_object()) {
    throw Error(ErrorClass::bad_parameter, "the body of " + req.method + " " + req.path + " must be a JSON object",
                "e.g. " + example);
  }
  return body;
}

}  // namespace colorlab::daemon
