#pragma once
// The transcript file colorlab doctor writes and tests/transcripts replays (docs/bring-up.md,
// "Transcript files"): JSON lines, UTF-8.
//   line 1   {"colorlab_transcript": 1, "port": ..., "plan": {"order": [...], "measure": bool}, ...}
//   then     {"t_ms": 1.2, "host": "4d44532c30340d0a"}      bytes colorlab sent (hex)
//            {"t_ms": 9.8, "device": "4f4b30300d0a"}        bytes the device answered (hex)
//            {"t_ms": 0.1, "settings": "4800 7E2 none"}     line settings colorlab applied
//            {"t_ms": 0.0, "mark": "probe ls110"}           a phase, for people
//   then     {"decoded": {...}}     what colorlab decoded while recording (never asserted)
//   last     {"expected": {"luminance": {"value": 245.5, "tolerance": 0.05}}, "source": "operator", ...}
// The expected values are the operator's (or, for the committed simulator recordings, the
// simulator's ground truth), so a replay checks the driver against them, not against itself.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/bringup/recording.hpp"

namespace colorlab::bringup {

inline constexpr int kTranscriptFormat = 1;

struct TranscriptFile {
  nlohmann::json header = nlohmann::json::object();
  std::vector<ByteEvent> events;
  nlohmann::json decoded = nlohmann::json::object();
  nlohmann::json expected = nlohmann::json::object();  // key -> {"value": v, "tolerance": t?, "unit": u?}
  std::string expected_source;                         // "operator", "simulator ground truth …", "" = unconfirmed
  std::string expected_note;
};

void write_transcript(const std::filesystem::path& path, const TranscriptFile& file);
// Throws Error{bad_data} naming the file and line for anything it cannot read.
TranscriptFile read_transcript(const std::filesystem::path& path);

std::string to_hex(std::string_view bytes);
// Throws Error{bad_data} for odd lengths or non-hex characters.
std::string from_hex(std::string_view hex);

// Whether `decoded` matches `expected` (one key); an empty string when it does, else why not.
std::string compare_expected(const std::string& key, const nlohmann::json& expected, const nlohmann::json& decoded);

}  // namespace colorlab::bringup
