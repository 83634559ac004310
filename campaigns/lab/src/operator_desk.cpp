#include "colorlab/campaigns/operator_desk.hpp"

#include <algorithm>

#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

using nlohmann::json;

json OperatorRequest::to_json() const {
  json j{{"id", id},
         {"execution_id", execution_id},
         {"action", action},
         {"prompt", prompt},
         {"options", options},
         {"default", default_option},
         {"timeout_s", timeout_s},
         {"details", details.is_null() ? json::object() : details},
         {"posted_at", posted_at},
         {"deadline", deadline},
         {"state", answer ? "answered" : "open"}};
  if (answer) {
    j["answer"] = *answer;
    j["answered_by"] = answered_by;
  }
  return j;
}

const OperatorRequest& OperatorDesk::post(OperatorRequest request) {
  auto id = request.id;
  auto [it, inserted] = open_.insert_or_assign(id, std::move(request));
  notify("posted", it->second);
  return it->second;
}

const OperatorRequest& OperatorDesk::answer(const std::string& id, const std::string& option, const std::string& who) {
  auto it = open_.find(id);
  if (it == open_.end() || it->second.answer) {
    throw Error(ErrorClass::not_found, "no open operator request '" + id + "'",
                "GET /v1/requests (colorlab requests) lists the open ones; it may have taken its default already");
  }
  auto& r = it->second;
  if (std::find(r.options.begin(), r.options.end(), option) == r.options.end()) {
    std::string list;
    for (const auto& o : r.options) list += (list.empty() ? "" : ", ") + o;
    throw Error(ErrorClass::bad_parameter, "'" + option + "' is not an answer to this request", "answer one of: " + list);
  }
  r.answer = option;
  r.answered_by = who.empty() ? "operator" : who;
  notify("answered", r);
  return r;
}

void OperatorDesk::take_default(const std::string& id) {
  auto it = open_.find(id);
  if (it == open_.end() || it->second.answer) return;
  it->second.answer = it->second.default_option;
  it->second.answered_by = "default";
  notify("defaulted", it->second);
}

void OperatorDesk::withdraw(const std::string& id, const std::string& why) {
  auto it = open_.find(id);
  if (it == open_.end()) return;
  OperatorRequest r = std::move(it->second);
  open_.erase(it);
  r.details["withdrawn"] = why;
  notify("withdrawn", r);
}

std::optional<OperatorRequest> OperatorDesk::take_answered(const std::string& id) {
  auto it = open_.find(id);
  if (it == open_.end() || !it->second.answer) return std::nullopt;
  OperatorRequest r = std::move(it->second);
  open_.erase(it);
  return r;
}

std::vector<OperatorRequest> OperatorDesk::pending() const {
  std::vector<OperatorRequest> out;
  for (const auto& [id, r] : open_) {
    if (!r.answer) out.push_back(r);
  }
  return out;  // ids are UUIDv7: map order is posting order
}

std::optional<OperatorRequest> OperatorDesk::find(const std::string& id) const {
  auto it = open_.find(id);
  if (it == open_.end()) return std::nullopt;
  return it->second;
}

}  // namespace colorlab::campaigns
