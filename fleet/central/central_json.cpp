#include "central_json.hpp"

#include <nlohmann/json.hpp>

namespace colorlab::fleet {

namespace {

using nlohmann::json;

// Scalars go through nlohmann's own serializer, so escaping (invalid UTF-8 replaced, as HttpResponse::json does)
// and the shortest round-trip form of a double stay exactly the bench's.
void append(std::string& out, const json& v) { out += v.dump(-1, ' ', false, json::error_handler_t::replace); }

void append_string(std::string& out, const std::string& s) {
  bool plain = true;
  for (unsigned char c : s) {
    if (c < 0x20 || c == '"' || c == '\\' || c >= 0x80) {
      plain = false;
      break;
    }
  }
  if (!plain) return append(out, json(s));
  out += '"';
  out += s;
  out += '"';
}

void append_optional(std::string& out, const std::optional<std::string>& s) {
  if (s) {
    append_string(out, *s);
  } else {
    out += "null";
  }
}

// MeasurementRecord::to_json's members, in the order a JSON object dumps them (by name).
void append_measurement(std::string& out, const store::MeasurementRecord& m) {
  out += '{';
  if (!m.data.is_null()) {
    out += "\"data\":";
    append(out, m.data);
    out += ',';
  }
  out += "\"instrument_id\":";
  append_string(out, m.instrument_id);
  out += ",\"measured_at\":";
  append_string(out, m.measured_at);
  out += ",\"quantity\":";
  append_string(out, m.quantity);
  out += ",\"seq\":";
  out += std::to_string(m.seq);
  out += m.simulated ? ",\"simulated\":true" : ",\"simulated\":false";
  out += ",\"step\":";
  append_string(out, m.step);
  out += ",\"unit\":";
  append_string(out, m.unit);
  out += ",\"value\":";
  if (m.value) {
    append(out, json(*m.value));
  } else {
    out += "null";
  }
  out += '}';
}

}  // namespace

std::string measurement_page_json(const store::MeasurementPage& page, const std::optional<std::string>& next_cursor,
                                  const std::optional<std::string>& next_link) {
  std::string out;
  out.reserve(64 + page.items.size() * 160);
  out += "{\"items\":[";
  for (std::size_t i = 0; i < page.items.size(); ++i) {
    if (i) out += ',';
    append_measurement(out, page.items[i]);
  }
  out += "],\"links\":{\"next\":";
  append_optional(out, next_link);
  out += "},\"next_cursor\":";
  append_optional(out, next_cursor);
  out += '}';
  return out;
}

}  // namespace colorlab::fleet
