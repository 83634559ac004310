#include "colorlab/campaigns/floor_photograph.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include <boost/asio/use_awaitable.hpp>

#include "colorlab/analysis/floor_luminance.hpp"
#include "colorlab/campaigns/frame_statistics.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/drivers/camera/asio_camera.hpp"
#include "colorlab/drivers/camera/camera_instrument.hpp"
#include "frame_keeping.hpp"

namespace colorlab::campaigns {

namespace cam = drivers::camera;
using nlohmann::json;

namespace {

// The simulated lab's floor view (sim/camera's FloorGeometry on a 3:2 sensor), as fractions of the frame: the front
// edge spans 94 % of the width, the back edge, 35 % farther away, less. A bench measures its own on a photograph.
constexpr double kSimCorners[4][2] = {{0.03, 0.78875}, {0.97, 0.78875}, {0.87873, 0.26733}, {0.12127, 0.26733}};

struct Spot {
  int row = 0, col = 0;
  double x_mm = 0, y_mm = 0;
};

struct FloorOptions {
  int frames = 8;
  std::array<std::array<double, 2>, 4> corners{};  // fractions of width, height
  double width_mm = 1200, depth_mm = 600, pitch_x_mm = 60, pitch_y_mm = 54, spot_mm = 20;
  std::vector<Spot> spots;
  std::vector<int> subsets;
  detail::KeepOptions keep;
};

Error bad(const std::string& what) { return Error(ErrorClass::bad_parameter, "lab.camera.photograph_floor: " + what); }

std::pair<double, double> pair_of(const json& o, const char* key, std::pair<double, double> d) {
  if (!o.contains(key)) return d;
  const json& v = o[key];
  if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number() || !(v[0].get<double>() > 0) ||
      !(v[1].get<double>() > 0)) {
    throw bad(std::string(key) + " must be {x, y}, both > 0 mm");
  }
  return {v[0].get<double>(), v[1].get<double>()};
}

FloorOptions parse(const json& in) {
  const json o = in.is_object() ? in : json::object();
  FloorOptions p;
  p.keep = detail::parse_keep(o, "camera.photograph_floor", {"average", "raw", "preview"}, {"preview"});
  if (o.contains("frames")) {
    if (!o["frames"].is_number_integer() || o["frames"].get<int>() < 1 || o["frames"].get<int>() > 256) throw bad("frames must be an integer from 1 to 256");
    p.frames = o["frames"].get<int>();
  }
  for (std::size_t i = 0; i < 4; ++i) p.corners[i] = {kSimCorners[i][0], kSimCorners[i][1]};
  if (o.contains("corners")) {
    const json& c = o["corners"];
    if (!c.is_array() || c.size() != 4) throw bad("corners must be four {x, y} (fractions of the frame: front-left, front-right, back-right, back-left)");
    for (std::size_t i = 0; i < 4; ++i) {
      if (!c[i].is_array() || c[i].size() != 2 || !c[i][0].is_number() || !c[i][1].is_number()) throw bad("corner " + std::to_string(i + 1) + " must be {x, y}");
      p.corners[i] = {c[i][0].get<double>(), c[i][1].get<double>()};
    }
  }
  std::tie(p.width_mm, p.depth_mm) = pair_of(o, "floor_mm", {p.width_mm, p.depth_mm});
  std::tie(p.pitch_x_mm, p.pitch_y_mm) = pair_of(o, "pitch_mm", {p.pitch_x_mm, p.pitch_y_mm});
  if (o.contains("spot_mm")) {
    if (!o["spot_mm"].is_number() || !(o["spot_mm"].get<double>() > 0) || o["spot_mm"].get<double>() > 200) throw bad("spot_mm must be a diameter from 0 to 200 mm");
    p.spot_mm = o["spot_mm"].get<double>();
  }
  if (!o.contains("spots") || !o["spots"].is_array() || o["spots"].empty()) throw bad("spots must list the floor spots to sample, {{row, col}, …}");
  for (const auto& s : o["spots"]) {
    const bool listed = s.is_array() && s.size() == 2 && s[0].is_number_integer() && s[1].is_number_integer();
    const bool named = s.is_object() && s.contains("row") && s.contains("col") && s["row"].is_number_integer() && s["col"].is_number_integer();
    if (!listed && !named) throw bad("each spot is {row, col} (0-based integers)");
    Spot spot{listed ? s[0].get<int>() : s["row"].get<int>(), listed ? s[1].get<int>() : s["col"].get<int>()};
    spot.x_mm = (spot.col + 0.5) * p.pitch_x_mm;
    spot.y_mm = (spot.row + 0.5) * p.pitch_y_mm;
    if (spot.row < 0 || spot.col < 0 || spot.x_mm > p.width_mm || spot.y_mm > p.depth_mm) {
      throw bad("spot row " + std::to_string(spot.row) + ", col " + std::to_string(spot.col) + " is off the floor");
    }
    p.spots.push_back(spot);
  }
  // The averages the speed-against-accuracy chart compares: 1, 2, 4, … frames, and all of them.
  for (int n = 1; n < p.frames; n *= 2) p.subsets.push_back(n);
  p.subsets.push_back(p.frames);
  return p;
}

std::array<std::array<double, 2>, 4> corners_px(const FloorOptions& p, std::size_t width, std::size_t height) {
  std::array<std::array<double, 2>, 4> c{};
  // A fraction is of the frame's edges; pixel centres are at integers.
  for (std::size_t i = 0; i < 4; ++i) c[i] = {p.corners[i][0] * double(width) - 0.5, p.corners[i][1] * double(height) - 0.5};
  return c;
}

// Filled on the camera's decode thread, read on the io thread after the series ended.
struct FloorSeries {
  bool ready = false;
  std::size_t width = 0, height = 0;
  std::array<std::array<double, 2>, 4> corners{};
  std::vector<std::vector<std::size_t>> pixels;  // per spot: x + y·width of its green pixels
  std::vector<std::array<double, 2>> centre_px;
  std::vector<std::vector<double>> sum;                  // per spot, per pixel
  std::vector<std::vector<analysis::SpotValue>> values;  // per spot, per subset reached
  int frames = 0;
};

void plan_spots(FloorSeries& s, const FloorOptions& p, const cam::RawImage& image) {
  s.width = image.width;
  s.height = image.height;
  s.corners = corners_px(p, s.width, s.height);
  const analysis::FloorMap map(s.corners, p.width_mm, p.depth_mm);
  const double r = p.spot_mm / 2;
  for (const auto& spot : p.spots) {
    const auto c = map.pixel_of(spot.x_mm, spot.y_mm);
    s.centre_px.push_back(c);
    double x0 = c[0], x1 = c[0], y0 = c[1], y1 = c[1];
    for (double dx : {-r, r})
      for (double dy : {-r, r}) {
        const auto q = map.pixel_of(spot.x_mm + dx, spot.y_mm + dy);
        x0 = std::min(x0, q[0]), x1 = std::max(x1, q[0]), y0 = std::min(y0, q[1]), y1 = std::max(y1, q[1]);
      }
    std::vector<std::size_t> px;
    const long xa = std::max(0L, long(std::floor(x0)) - 1), xb = std::min(long(s.width) - 1, long(std::ceil(x1)) + 1);
    const long ya = std::max(0L, long(std::floor(y0)) - 1), yb = std::min(long(s.height) - 1, long(std::ceil(y1)) + 1);
    for (long y = ya; y <= yb; ++y)
      for (long x = xa; x <= xb; ++x) {
        // Green: the channel closest to the luminance the meter weighs by V(λ); a mono sensor's every pixel.
        if (image.cfa.is_mosaic() && image.cfa.at(std::size_t(y), std::size_t(x)) != cam::CfaColor::green) continue;
        const auto f = map.floor_of(double(x), double(y));
        if ((f[0] - spot.x_mm) * (f[0] - spot.x_mm) + (f[1] - spot.y_mm) * (f[1] - spot.y_mm) <= r * r) px.push_back(std::size_t(y) * s.width + std::size_t(x));
      }
    if (px.empty()) {
      // A spot smaller than a pixel: the pixel nearest its centre's green, so every spot has a value.
      const long x = std::clamp(long(std::lround(c[0])), 0L, long(s.width) - 1), y = std::clamp(long(std::lround(c[1])), 0L, long(s.height) - 1);
      const long gx = image.cfa.is_mosaic() && image.cfa.at(std::size_t(y), std::size_t(x)) != cam::CfaColor::green ? (x > 0 ? x - 1 : x + 1) : x;
      px.push_back(std::size_t(y) * s.width + std::size_t(gx));
    }
    s.pixels.push_back(std::move(px));
  }
  for (const auto& px : s.pixels) s.sum.emplace_back(px.size(), 0.0);
  s.values.resize(p.spots.size());
  s.ready = true;
}

json spot_json(const Spot& spot, const std::array<double, 2>& px, std::size_t pixels) {
  return {
      {"row", spot.row},
      {"col", spot.col},
      {"x_mm", spot.x_mm},
      {"y_mm", spot.y_mm},
      {"px", {px[0], px[1]}},
      {"pixels", pixels},
      {"signal", json::array()},
      {"stdev", json::array()},
  };
}

}  // namespace

boost::asio::awaitable<json> photograph_floor(cam::CameraInstrument& instrument, const json& options, FrameKeeper* keeper) {
  const FloorOptions p = parse(options);
  auto& camera = instrument.camera();
  co_await use_sensor_counts(camera);
  auto series = std::make_shared<FloorSeries>();
  auto kept = std::make_shared<detail::SeriesFrames>();
  kept->keep_first = p.keep.wants("raw");
  const bool keeping = keeper && p.keep.any();
  auto sink = [series, kept, keeping, &p](const cam::RawImage& image) {
    if (keeping) kept->add(image);
    auto& s = *series;
    if (!s.ready) plan_spots(s, p, image);
    if (image.width != s.width || image.height != s.height) throw Error(ErrorClass::bad_data, "the camera changed its frame size within a series");
    for (std::size_t k = 0; k < s.pixels.size(); ++k) {
      for (std::size_t i = 0; i < s.pixels[k].size(); ++i) {
        const std::size_t x = s.pixels[k][i] % s.width, y = s.pixels[k][i] / s.width;
        s.sum[k][i] += double(image.at(x, y)) - double(image.black_at(x, y));
      }
    }
    ++s.frames;
    if (std::find(p.subsets.begin(), p.subsets.end(), s.frames) == p.subsets.end()) return;
    std::vector<double> mean;
    for (std::size_t k = 0; k < s.pixels.size(); ++k) {
      mean.resize(s.sum[k].size());
      for (std::size_t i = 0; i < mean.size(); ++i) mean[i] = s.sum[k][i] / s.frames;
      s.values[k].push_back(analysis::robust_spot_value(mean));
    }
  };
  cam::CaptureReport report =
      co_await cam::async_capture(camera, static_cast<std::size_t>(p.frames), sink, boost::asio::use_awaitable);
  if (!report.complete()) {
    if (report.error) throw *report.error;
    throw Error(ErrorClass::hardware_fail, "the camera delivered " + std::to_string(report.delivered) + " of " +
                                               std::to_string(report.requested) + " frames");
  }
  json blobs = json::array();
  if (keeping) {
    detail::KeepRequest request{p.keep, "", kept.get(), {}, {}};
    for (const auto& f : report.saved_files) {
      if (detail::is_raw_file(f)) request.raw_files.push_back(f);
    }
    blobs = co_await detail::keep_on_worker(keeper, std::move(request));
  }
  const auto& s = *series;
  json spots = json::array();
  for (std::size_t k = 0; k < p.spots.size(); ++k) {
    json j = spot_json(p.spots[k], s.centre_px[k], s.pixels[k].size());
    for (const auto& v : s.values[k]) {
      j["signal"].push_back(v.value);
      j["stdev"].push_back(v.stdev);
    }
    spots.push_back(j);
  }
  json corners = json::array();
  for (const auto& c : s.corners) corners.push_back({c[0], c[1]});
  co_return json{
      {"instrument", instrument.id()},
      {"frames", p.frames},
      {"width", s.width},
      {"height", s.height},
      {"corners_px", corners},
      {"spot_mm", p.spot_mm},
      {"subsets", p.subsets},
      {"unit", "DN above black (green)"},
      {"spots", spots},
      {"blobs", blobs},
  };
}

json dry_floor_photograph(const json& options, const std::string& instrument) {
  const FloorOptions p = parse(options);
  constexpr std::size_t kWidth = 3504, kHeight = 2336;  // the simulated lab's sensor
  const auto c = corners_px(p, kWidth, kHeight);
  const analysis::FloorMap map(c, p.width_mm, p.depth_mm);
  json spots = json::array();
  for (const auto& spot : p.spots) {
    json j = spot_json(spot, map.pixel_of(spot.x_mm, spot.y_mm), 100);
    for (std::size_t i = 0; i < p.subsets.size(); ++i) {
      j["signal"].push_back(1000.0);
      j["stdev"].push_back(10.0);
    }
    spots.push_back(j);
  }
  json corners = json::array();
  for (const auto& q : c) corners.push_back({q[0], q[1]});
  return json{
      {"instrument", instrument},
      {"frames", p.frames},
      {"width", kWidth},
      {"height", kHeight},
      {"corners_px", corners},
      {"spot_mm", p.spot_mm},
      {"subsets", p.subsets},
      {"unit", "DN above black (green)"},
      {"spots", spots},
      {"blobs", json::array()},
  };
}

}  // namespace colorlab::campaigns
