#include "chart_sampling.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "colorlab/analysis/chart_locate.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::campaigns::detail {

using nlohmann::json;
namespace ca = analysis;

namespace {

// Sums one format's frames; every frame must be the same kind of image as the first.
class Summer {
 public:
  explicit Summer(std::string format) { out_.format = std::move(format); }
  void add(const ca::Photo& p, const std::filesystem::path& path) {
    if (sum_.empty()) {
      first_ = {p.width, p.height, p.channels, p.type, {}};
      sum_.assign(static_cast<std::size_t>(p.width) * p.height * p.channels, 0);
    } else if (p.width != first_.width || p.height != first_.height || p.channels != first_.channels || p.type != first_.type) {
      throw Error(ErrorClass::bad_data,
                  path.filename().string() + " is not the same kind of image as " +
                      std::filesystem::path(out_.files.front()).filename().string() +
                      " (size, channels or bit depth differ within one series)",
                  "the camera's settings changed during the series: photograph the chart again");
    }
    if (p.type == ca::SampleType::u8) {
      for (std::size_t i = 0; i < sum_.size(); ++i) sum_[i] += p.bytes[i];
    } else {
      const auto* s = reinterpret_cast<const std::uint16_t*>(p.bytes.data());
      for (std::size_t i = 0; i < sum_.size(); ++i) sum_[i] += s[i];
    }
    out_.files.push_back(path.string());
  }
  AveragedPhoto result() && {
    out_.frames = static_cast<int>(out_.files.size());
    out_.bits = first_.type == ca::SampleType::u8 ? 8 : 16;
    out_.scale = std::ldexp(1.0, 16 - out_.bits);
    out_.photo.width = first_.width;
    out_.photo.height = first_.height;
    out_.photo.channels = first_.channels;
    out_.photo.type = ca::SampleType::u16;
    out_.photo.bytes.resize(sum_.size() * sizeof(std::uint16_t));
    auto* dst = reinterpret_cast<std::uint16_t*>(out_.photo.bytes.data());
    const double k = out_.scale / out_.frames;
    for (std::size_t i = 0; i < sum_.size(); ++i) dst[i] = static_cast<std::uint16_t>(std::min(65535.0, std::round(sum_[i] * k)));
    sum_ = {};
    return std::move(out_);
  }

 private:
  AveragedPhoto out_;
  ca::Photo first_;
  std::vector<std::uint32_t> sum_;
};

}  // namespace

AveragedPhoto average_files(const std::string& format, const std::vector<std::filesystem::path>& files) {
  if (files.empty()) throw Error(ErrorClass::internal, "average_files: no " + format + " files");
  Summer summer(format);
  for (const auto& path : files) summer.add(ca::read_photo(path), path);
  return std::move(summer).result();
}

std::map<std::string, AveragedPhoto> average_tiffs(const std::vector<std::filesystem::path>& files) {
  // Each file is read once and goes to the sum of its sample type.
  std::map<std::string, Summer> sums;
  for (const auto& path : files) {
    ca::Photo p = ca::read_photo(path);
    const std::string format = p.type == ca::SampleType::u8 ? "tiff8" : "tiff16";
    sums.try_emplace(format, format).first->second.add(p, path);
  }
  std::map<std::string, AveragedPhoto> out;
  for (auto& [format, summer] : sums) out[format] = std::move(summer).result();
  return out;
}

namespace {

// What every answer about one format's photograph starts with, located or refused.
json photograph_fields(const AveragedPhoto& a) {
  return json{
      {"format", a.format},
      {"frames", a.frames},
      {"files", a.files},
      {"width", a.photo.width},
      {"height", a.photo.height},
      {"bits", a.bits},
  };
}

}  // namespace

json locate_and_sample(const AveragedPhoto& a, const SamplingOptions& options) {
  ca::PhotoView view = a.photo.view();
  view.bit_depth = 16;  // scaled to 16 bits: the robust band scales with it
  view.black_level = a.black_level * a.scale;
  view.cfa = a.cfa;
  ca::LocateOptions lo;
  lo.sample_fraction = options.sample_fraction;
  lo.min_confidence = options.min_confidence;
  lo.reference = options.reference;
  if (auto it = options.corners.find(a.format); it != options.corners.end()) lo.corners = it->second;
  ca::ChartLocation loc;
  try {
    loc = ca::locate_chart(view, options.chart, lo);
  } catch (const Error& e) {
    const bool refusal = e.cls() == ErrorClass::not_found || e.cls() == ErrorClass::needs_operator ||
                         (e.cls() == ErrorClass::bad_parameter && lo.corners);
    if (options.return_refusals && refusal) {
      json refused = photograph_fields(a);
      refused["chart"] = std::string(ca::to_string(options.chart));
      refused["from_corners"] = lo.corners.has_value();
      refused["refused"] = {{"error", std::string(to_string(e.cls()))}, {"message", e.info().message}, {"hint", e.hint()}};
      return refused;
    }
    // Which of the four photographs the locator refused matters to the operator.
    ErrorInfo info = e.info();
    info.message = "the " + a.format + " photograph of the chart: " + info.message;
    throw Error(std::move(info));
  }
  json corners = json::array();
  for (const auto& c : loc.corners) corners.push_back({c.x, c.y});
  json ids = json::array(), values = json::array(), detected = json::array();
  for (const auto& p : loc.patches) {
    ids.push_back(p.id);
    json v = json::array();
    for (int c = 0; c < 3; ++c) {
      const auto& pv = p.value[static_cast<std::size_t>(p.channels == 3 ? c : 0)];
      // Raw counts above black: the linear signal the characterizations regress; processed
      // values stay as encoded (0–255 or 0–65535).
      v.push_back((pv.value - view.black_level) / a.scale);
    }
    values.push_back(v);
    detected.push_back(p.detected);
  }
  json located = photograph_fields(a);
  located.update(json{{"black_subtracted", a.cfa.has_value()},
                      {"chart", std::string(ca::to_string(loc.type))},
                      {"confidence", loc.confidence},
                      {"rotation_deg", loc.rotation_deg},
                      {"from_corners", loc.from_corners},
                      {"corners", corners},
                      {"patches_detected", loc.patches_detected},
                      {"reprojection_rms_px", loc.reprojection_rms_px},
                      {"check", {
                                    {"passed", loc.check.passed},
                                    {"method", loc.check.method},
                                    {"worst_disagreement", loc.check.worst_disagreement},
                                    {"worst_patch", loc.check.worst_patch},
                                    {"gradient_x", loc.check.gradient_x},
                                    {"gradient_y", loc.check.gradient_y},
                                }},
                      {"ids", ids},
                      {"values", values},
                      {"detected", detected},
                      {"notes", loc.notes}});
  if (options.centres) {
    json observed = json::array();
    for (const auto& p : loc.patches)
      if (p.detected) observed.push_back({{"id", p.id}, {"x", p.observed.x}, {"y", p.observed.y}});
    located["observed_px"] = std::move(observed);
  }
  return located;
}

}  // namespace colorlab::campaigns::detail
