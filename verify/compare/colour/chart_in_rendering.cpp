// The chart in a rendering, found by the same locator that found it in the photograph (analysis::locate_chart), so
// a rendering made from any view that shows the whole chart is sampled on its own patches — no assumption that it
// was rendered with the photograph's camera.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <vector>

#include "colorlab/analysis/chart_locate.hpp"
#include "colorlab/core/error.hpp"
#include "colour_from_runs.hpp"
#include "rendering_sample.hpp"

namespace colorlab::verify {

using nlohmann::json;
namespace ca = analysis;

ChartInRendering locate_chart_in_rendering(const Rendering& r, const json& chart_read) {
  if (r.width <= 0 || r.height <= 0 || r.pixels.empty()) throw Error(ErrorClass::bad_data, "the rendering has no pixels");
  if (r.encoding == Encoding::spectral && r.reflective)
    throw Error(ErrorClass::unsupported, "a reflective spectral rendering has no luminance to find the chart in",
                "render the scene's radiance (JCGT's emissive S0 layer)");
  // Luminance in the renderer's unit, then 16-bit linear counts with the image's bright end near full scale (the
  // 99.9th percentile, so a lamp in view does not leave the chart in the lowest bits). Y is linear in the channels,
  // so it is one dot product per pixel with the conversion's Y row (read off unit vectors), in float: at 3504 × 2336
  // the per-pixel 3 × N product and two double copies of the image cost more than the locator itself (perf,
  // bench_verify_speed).
  const detail::ToXyz to_xyz(r);
  const int n = r.channels();
  std::vector<float> y_row(static_cast<std::size_t>(n));
  for (int c = 0; c < n; ++c) y_row[static_cast<std::size_t>(c)] = static_cast<float>(to_xyz(Eigen::VectorXd::Unit(n, c)).Y);
  std::vector<float> y(static_cast<std::size_t>(r.width) * static_cast<std::size_t>(r.height));
  for (std::size_t i = 0; i < y.size(); ++i) {
    const float* p = r.pixels.data() + i * static_cast<std::size_t>(n);
    float sum = 0;
    for (int c = 0; c < n; ++c) sum += y_row[static_cast<std::size_t>(c)] * p[c];
    y[i] = std::max(0.0f, sum);
  }
  std::vector<float> sorted = y;
  const auto k = static_cast<std::ptrdiff_t>(0.999 * static_cast<double>(sorted.size() - 1));
  std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
  const double top = sorted[static_cast<std::size_t>(k)];
  std::vector<float>().swap(sorted);
  if (!(top > 0)) throw Error(ErrorClass::bad_data, "the rendering is black: no chart to find in it");
  std::vector<std::uint16_t> grey(y.size());
  const double to_counts = 60000.0 / top;
  for (std::size_t i = 0; i < y.size(); ++i) grey[i] = static_cast<std::uint16_t>(std::min(65535.0, std::round(y[i] * to_counts)));

  ca::PhotoView view;
  view.data = grey.data();
  view.width = r.width;
  view.height = r.height;
  view.channels = 1;
  view.type = ca::SampleType::u16;
  view.bit_depth = 16;

  // The chart-read's luminances tell the locator which way up the chart is and what a dark patch looks like.
  const std::string chart = chart_read.contains("params") ? chart_read["params"].value("chart", std::string("sg")) : "sg";
  const ca::ChartType type = ca::chart_type_from_string(chart);
  const ca::ChartLayout& layout = ca::chart_layout(type);
  std::map<std::string, double> y_of;
  for (const auto& m : chart_read["measurements"]) {
    if (m.value("step", "").rfind("patch/", 0) != 0 || !m.contains("data")) continue;
    const json& d = m["data"];
    if (d.contains("id") && d.contains("XYZ") && d["XYZ"].is_array() && d["XYZ"].size() == 3)
      y_of.emplace(d["id"].get<std::string>(), d["XYZ"][1].get<double>() / 100.0);
  }
  ca::LocateOptions lo;
  ca::ChartReference ref;
  for (const auto& id : layout.ids) {
    auto it = y_of.find(id);
    ref.luminance.push_back(it == y_of.end() ? std::numeric_limits<double>::quiet_NaN() : it->second);
  }
  lo.reference = ref;
  ca::ChartLocation loc;
  try {
    loc = ca::locate_chart(view, type, lo);
  } catch (const Error& e) {
    ErrorInfo info = e.info();
    info.message = "the chart was not found in the rendering: " + info.message;
    info.hint = "the rendering must show the whole " + std::string(layout.name) + " lit, as the photograph did (colorlab scene's camera)";
    throw Error(std::move(info));
  }
  ChartInRendering out;
  out.confidence = loc.confidence;
  out.accuracy_px = loc.reprojection_rms_px;
  for (const auto& p : loc.patches) {
    out.ids.push_back(p.id);
    out.regions.push_back(PixelRect{static_cast<int>(p.region.x), static_cast<int>(p.region.y), static_cast<int>(p.region.width),
                                    static_cast<int>(p.region.height)});
  }
  return out;
}

}  // namespace colorlab::verify
