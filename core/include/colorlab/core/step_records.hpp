#pragma once
// What one committed step of a campaign is made of, as plain records: the engine fills them, the
// daemon's store writes them in one transaction. They live here, below both, so the engine need not
// know SQLite and the store need not know Lua, the lab or its procedures — and neither converts the
// other's mirror copies field by field.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace colorlab::records {

// One lab call of a run and its answer, as journaled: a resumed run is answered from these.
struct JournalEntry {
  std::int64_t seq = 0;  // 0-based position of the call in the script's run
  std::string call;      // "meter.measure", "lamps.select", ...
  nlohmann::json args;   // the call's arguments as given
  nlohmann::json result;
};

// One lab.record of a script.
struct Measurement {
  std::string step;  // unique within the run
  std::string instrument_id;
  bool simulated = false;  // the instrument that measured it is simulated
  std::string quantity;
  std::optional<double> value;
  std::string unit;
  nlohmann::json data;
};

// One live call's duration: `lab_seconds` per unit (a frame × format for photographs, a frame for
// captures, the call otherwise), wall time × the lab's time scale, minus waits the script itself
// asked for (a dimmer's settle_s), which the dry run adds back exactly.
struct CallTiming {
  std::string key;
  double lab_seconds = 0;
};

// A file kept in the blob store (durable before the step is committed). Where a procedure keeps it,
// `name` is the name within the call; in a committed step it is the run's name "<call>#<seq>/<name>".
struct BlobRef {
  std::string sha256;
  std::string name;
  std::string kind;  // raw, average, tiff16, tiff8, jpeg, preview
  std::string media_type;
  std::uint64_t size = 0;
  nlohmann::json meta = nlohmann::json::object();
};

// One committed step: everything since the previous commit, stored in one transaction.
struct Step {
  std::vector<JournalEntry> journal;
  std::vector<Measurement> measurements;
  double progress = 0;
  std::string label;
  // How long each live call took (none for replayed ones, nor for calls that were suspended):
  // what the dry run estimates from.
  std::vector<CallTiming> timings;
  // What the step's calls kept, named in the run, in the order they were kept.
  std::vector<BlobRef> blobs;
};

}  // namespace colorlab::records
