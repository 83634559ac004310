#include "colorlab/bringup/transcript_file.hpp"

#include <cmath>
#include <fstream>

#include "colorlab/core/error.hpp"

namespace colorlab::bringup {

using nlohmann::json;

std::string to_hex(std::string_view bytes) {
  static constexpr char digits[] = "0123456789abcdef";
  std::string out;
  out.reserve(bytes.size() * 2);
  for (unsigned char c : bytes) {
    out += digits[c >> 4];
    out += digits[c & 0x0F];
  }
  return out;
}

std::string from_hex(std::string_view hex) {
  auto nibble = [&](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    throw Error(ErrorClass::bad_data, "'" + std::string(1, c) + "' is not a hex digit");
  };
  if (hex.size() % 2 != 0) throw Error(ErrorClass::bad_data, "hex bytes of odd length " + std::to_string(hex.size()));
  std::string out;
  out.reserve(hex.size() / 2);
  for (std::size_t i = 0; i < hex.size(); i += 2) out += static_cast<char>(nibble(hex[i]) * 16 + nibble(hex[i + 1]));
  return out;
}

void write_transcript(const std::filesystem::path& path, const TranscriptFile& file) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(ErrorClass::io_error, "cannot write the transcript " + path.string(), "check the --record directory");
  json header = file.header;
  header["colorlab_transcript"] = kTranscriptFormat;
  out << header.dump() << "\n";
  for (const auto& e : file.events) {
    json line{{"t_ms", std::round(e.t_ms * 1000.0) / 1000.0}};
    switch (e.kind) {
      case ByteEvent::Kind::host: line["host"] = to_hex(e.data); break;
      case ByteEvent::Kind::device: line["device"] = to_hex(e.data); break;
      case ByteEvent::Kind::settings: line["settings"] = e.data; break;
      case ByteEvent::Kind::mark: line["mark"] = e.data; break;
    }
    out << line.dump() << "\n";
  }
  out << json{{"decoded", file.decoded}}.dump() << "\n";
  json expected{{"expected", file.expected}, {"source", file.expected_source}};
  if (!file.expected_note.empty()) expected["note"] = file.expected_note;
  out << expected.dump() << "\n";
  if (!out) throw Error(ErrorClass::io_error, "writing the transcript " + path.string() + " failed");
}

TranscriptFile read_transcript(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorClass::not_found, "cannot read the transcript " + path.string());
  TranscriptFile f;
  std::string text;
  int n = 0;
  bool have_header = false;
  while (std::getline(in, text)) {
    ++n;
    if (text.empty()) continue;
    auto where = path.string() + ":" + std::to_string(n);
    json line;
    try {
      line = json::parse(text);
    } catch (const json::exception& e) {
      throw Error(ErrorClass::bad_data, where + ": not JSON (" + e.what() + ")");
    }
    if (!line.is_object()) throw Error(ErrorClass::bad_data, where + ": a transcript line is a JSON object");
    try {
      if (!have_header) {
        if (!line.contains("colorlab_transcript")) {
          throw Error(ErrorClass::bad_data, where + ": the first line must be the header with \"colorlab_transcript\"");
        }
        if (line["colorlab_transcript"] != kTranscriptFormat) {
          throw Error(ErrorClass::bad_data, where + ": transcript format " + line["colorlab_transcript"].dump() +
                                                " is not the " + std::to_string(kTranscriptFormat) + " this colorlab reads");
        }
        f.header = line;
        have_header = true;
      } else if (line.contains("host") || line.contains("device")) {
        bool host = line.contains("host");
        f.events.push_back(ByteEvent{host ? ByteEvent::Kind::host : ByteEvent::Kind::device, line.value("t_ms", 0.0),
                                     from_hex(line[host ? "host" : "device"].get<std::string>())});
      } else if (line.contains("settings")) {
        f.events.push_back(ByteEvent{ByteEvent::Kind::settings, line.value("t_ms", 0.0), line["settings"].get<std::string>()});
      } else if (line.contains("mark")) {
        f.events.push_back(ByteEvent{ByteEvent::Kind::mark, line.value("t_ms", 0.0), line["mark"].get<std::string>()});
      } else if (line.contains("decoded")) {
        f.decoded = line["decoded"];
      } else if (line.contains("expected")) {
        f.expected = line["expected"];
        f.expected_source = line.value("source", std::string());
        f.expected_note = line.value("note", std::string());
        if (!f.expected.is_object()) throw Error(ErrorClass::bad_data, where + ": \"expected\" must be an object");
      } else {
        throw Error(ErrorClass::bad_data, where + ": a line with none of host, device, settings, mark, decoded, expected");
      }
    } catch (const json::exception& e) {
      throw Error(ErrorClass::bad_data, where + ": " + e.what());
    } catch (const Error& e) {
      if (e.info().message.rfind(path.string(), 0) == 0) throw;
      throw Error(ErrorClass::bad_data, where + ": " + e.info().message);
    }
  }
  if (!have_header) throw Error(ErrorClass::bad_data, path.string() + " is empty: no transcript header");
  return f;
}

namespace {

bool near(double want, double got, double tol) { return std::isfinite(got) && std::abs(got - want) <= tol; }

}  // namespace

std::string compare_expected(const std::string& key, const json& expected, const json& decoded) {
  json want = expected.is_object() && expected.contains("value") ? expected["value"] : expected;
  double tol = expected.is_object() ? expected.value("tolerance", 0.0) : 0.0;
  if (decoded.is_null()) return key + ": expected " + want.dump() + ", the driver decoded nothing";
  if (want.is_number()) {
    if (!decoded.is_number()) return key + ": expected " + want.dump() + ", decoded " + decoded.dump();
    if (!near(want.get<double>(), decoded.get<double>(), tol)) {
      return key + ": expected " + want.dump() + " ± " + std::to_string(tol) + ", decoded " + decoded.dump();
    }
    return {};
  }
  if (want.is_array()) {
    if (!decoded.is_array() || decoded.size() != want.size()) {
      return key + ": expected " + std::to_string(want.size()) + " values, decoded " + decoded.dump();
    }
    for (std::size_t i = 0; i < want.size(); ++i) {
      auto why = compare_expected(key + "[" + std::to_string(i) + "]", json{{"value", want[i]}, {"tolerance", tol}}, decoded[i]);
      if (!why.empty()) return why;
    }
    return {};
  }
  if (want != decoded) return key + ": expected " + want.dump() + ", decoded " + decoded.dump();
  return {};
}

}  // namespace colorlab::bringup
