#include "colorlab/campaigns/luminance_spot.hpp"

#include <cmath>

#include "colorlab/core/error.hpp"

namespace colorlab::campaigns {

nlohmann::json LuminanceSpot::parameters() const {
  return {{"readings", {{"type", "integer"}, {"default", 1}, {"minimum", 1}, {"maximum", 1000}}},
          {"instrument", {{"type", "string"}, {"default", ""}, {"description", "LS-110 id; empty = the first one"}}}};
}

void LuminanceSpot::validate(const nlohmann::json& params) const {
  if (!params.is_object()) throw Error(ErrorClass::bad_parameter, "params must be a JSON object");
  for (const auto& [key, value] : params.items()) {
    if (key == "readings") {
      if (!value.is_number_integer() || value.get<long long>() < 1 || value.get<long long>() > 1000) {
        throw Error(ErrorClass::bad_parameter, "params.readings must be an integer from 1 to 1000");
      }
    } else if (key == "instrument") {
      if (!value.is_string()) throw Error(ErrorClass::bad_parameter, "params.instrument must be a string");
    } else {
      throw Error(ErrorClass::bad_parameter, "unknown parameter params." + key + " for luminance-spot",
                  "parameters: readings, instrument");
    }
  }
}

boost::asio::awaitable<nlohmann::json> LuminanceSpot::run(CampaignContext& ctx) const {
  int readings = ctx.params.value("readings", 1);
  std::string wanted = ctx.params.value("instrument", std::string());
  std::shared_ptr<drivers::LuminanceMeter> meter;
  if (wanted.empty()) {
    meter = ctx.instruments.first_with<drivers::LuminanceMeter>(drivers::Capability::luminance);
  } else {
    meter = std::dynamic_pointer_cast<drivers::LuminanceMeter>(ctx.instruments.find(wanted));
    if (!meter) throw Error(ErrorClass::not_found, "no luminance meter with id '" + wanted + "'");
  }

  double sum = 0, sum_sq = 0;
  int done = 0;
  for (int i = 0; i < readings; ++i) {
    std::string step = "reading/" + std::to_string(i);
    ctx.progress(static_cast<double>(i) / readings, step);
    if (ctx.recorder.has_step(step)) continue;
    auto r = co_await meter->measure_luminance();
    ctx.recorder.record(Measurement{step, meter->id(), "luminance", r.luminance, r.unit, {{"raw", r.raw_reply}}});
    sum += r.luminance;
    sum_sq += r.luminance * r.luminance;
    ++done;
  }
  ctx.progress(1.0, "done");
  nlohmann::json summary{{"readings", done}, {"unit", "cd/m2"}};
  if (done > 0) {
    double mean = sum / done;
    summary["mean"] = mean;
    summary["stdev"] = done > 1 ? std::sqrt(std::max(0.0, (sum_sq - done * mean * mean) / (done - 1))) : 0.0;
  }
  co_return summary;
}

}  // namespace colorlab::campaigns
