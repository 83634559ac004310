#pragma once
// A campaign is a named, parameterised procedure. It runs as a coroutine on the daemon's
// executor, records each measurement under a stable step key (so a resumed run can skip what
// is already stored), and reports progress. It returns a JSON summary for the run record.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <boost/asio/awaitable.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/campaigns/instrument_set.hpp"

namespace colorlab::campaigns {

struct Measurement {
  std::string step;  // stable key within the run, e.g. "spot/r3c4/reading/2"
  std::string instrument_id;
  std::string quantity;  // "luminance", "reflectance_spectrum", ...
  double value = 0;      // scalar value, or NaN when the payload is in `data`
  std::string unit;
  nlohmann::json data;  // spectra, raw replies, positions
};

// Implemented by the daemon's store; a recorded measurement is durable when record() returns.
class RunRecorder {
 public:
  virtual ~RunRecorder() = default;
  virtual void record(const Measurement& m) = 0;
  virtual bool has_step(const std::string& step) const = 0;
};

struct CampaignContext {
  const InstrumentSet& instruments;
  RunRecorder& recorder;
  nlohmann::json params;
  std::function<void(double fraction, const std::string& step)> progress;
};

class Campaign {
 public:
  virtual ~Campaign() = default;
  virtual std::string name() const = 0;
  virtual std::string description() const = 0;
  // Parameters with defaults, as shown to clients (GET /v1/campaigns).
  virtual nlohmann::json parameters() const = 0;
  // Throws Error{bad_parameter} naming the parameter before anything is measured.
  virtual void validate(const nlohmann::json& params) const = 0;
  virtual boost::asio::awaitable<nlohmann::json> run(CampaignContext& ctx) const = 0;
};

class CampaignRegistry {
 public:
  // Every campaign colorlab ships.
  static CampaignRegistry with_builtin_campaigns();

  void add(std::unique_ptr<Campaign> c);
  const Campaign* find(const std::string& name) const;
  std::vector<const Campaign*> all() const;

 private:
  std::vector<std::unique_ptr<Campaign>> campaigns_;
};

}  // namespace colorlab::campaigns
