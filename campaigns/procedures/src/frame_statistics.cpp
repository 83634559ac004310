#include "colorlab/campaigns/frame_statistics.hpp"

#include <algorithm>
#include <memory>

#include <boost/asio/use_awaitable.hpp>

#include "colorlab/analysis/patch_stats.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/drivers/camera/asio_camera.hpp"
#include "colorlab/drivers/camera/camera_instrument.hpp"
#include "frame_keeping.hpp"

namespace colorlab::campaigns {

using nlohmann::json;
namespace cam = drivers::camera;

namespace {

// The region of every frame, split into its CFA planes (R, G, B; greens pooled would mix two
// populations, so only the first green is kept) as float images.
struct RegionFrames {
  std::size_t x = 0, y = 0, width = 0, height = 0;
  bool mosaic = true;
  std::vector<std::vector<float>> planes[3];  // [channel][frame] → (width/2)×(height/2) samples
};

constexpr const char* kChannelNames[3] = {"R", "G", "B"};

// Table 2 needs a uniform patch: on the first frame, the 32×32 window with the smallest spread
// among those whose level is mid-range (not black, not clipped), on a 32-pixel grid.
void choose_uniform_region(const cam::RawImage& image, RegionFrames& g) {
  constexpr std::size_t kSize = 32;
  double full = static_cast<double>(image.white_level) - image.black_level[0];
  double best = -1;
  for (std::size_t y = 0; y + kSize <= image.height; y += kSize) {
    for (std::size_t x = 0; x + kSize <= image.width; x += kSize) {
      // Same-colour samples only (one of each 2×2 cell), so a Bayer mosaic does not count as texture.
      double sum = 0, sum_sq = 0;
      std::size_t n = 0;
      for (std::size_t yy = 0; yy < kSize; yy += 2) {
        for (std::size_t xx = 0; xx < kSize; xx += 2) {
          double v = static_cast<double>(image.at(x + xx, y + yy)) - image.black_at(x + xx, y + yy);
          sum += v;
          sum_sq += v * v;
          ++n;
        }
      }
      double mean = sum / n;
      if (full > 0 && (mean < 0.15 * full || mean > 0.7 * full)) continue;
      double var = sum_sq / n - mean * mean;
      if (best < 0 || var < best) {
        best = var;
        g.x = x;
        g.y = y;
      }
    }
  }
  if (best < 0) {  // nothing mid-range: the centre
    g.x = (image.width / 2 - kSize / 2) & ~std::size_t{1};
    g.y = (image.height / 2 - kSize / 2) & ~std::size_t{1};
  }
  g.width = g.height = kSize;
}

}  // namespace

boost::asio::awaitable<void> use_sensor_counts(cam::Camera& camera) {
  // Averaging needs the sensor's counts: ask a GenICam camera for its raw Bayer (or mono) format.
  const auto formats = camera.limits().pixel_formats;
  if (formats.empty() || camera.settings().pixel_format) co_return;
  cam::CameraSettings settings;
  settings.pixel_format = formats.front();
  for (auto preferred : {cam::PixelFormat::bayer_rg16, cam::PixelFormat::bayer_rg12}) {
    if (std::find(formats.begin(), formats.end(), preferred) != formats.end()) settings.pixel_format = preferred;
  }
  auto error = co_await cam::async_configure(camera, settings, boost::asio::use_awaitable);
  if (error) throw *error;
}

boost::asio::awaitable<json> capture_noise_table(cam::CameraInstrument& instrument, const json& options, FrameKeeper* keeper) {
  const int frames = options.value("frames", 25);
  const auto keep = detail::parse_keep(options, "camera.capture", {"average", "raw", "preview"}, {"average", "raw", "preview"});
  auto series = std::make_shared<detail::SeriesFrames>();
  series->keep_first = keep.wants("raw");
  const bool keeping = keeper && keep.any();
  if (frames < 1 || frames > 256) throw Error(ErrorClass::bad_parameter, "camera.capture: frames must be from 1 to 256");
  auto& camera = instrument.camera();
  co_await use_sensor_counts(camera);

  auto region = std::make_shared<RegionFrames>();
  if (options.contains("region") && options["region"].is_array() && options["region"].size() == 4) {
    const auto& r = options["region"];
    for (const auto& v : r) {
      if (!v.is_number_integer() || v.get<long long>() < 0) throw Error(ErrorClass::bad_parameter, "camera.capture: region must be {x, y, w, h} in pixels");
    }
    region->x = r[0];
    region->y = r[1];
    region->width = r[2];
    region->height = r[3];
    if (region->width < 4 || region->height < 4) throw Error(ErrorClass::bad_parameter, "camera.capture: region width and height must be ≥ 4");
  }
  // Runs on the camera's decode thread; the campaign reads `region` only after the series ends.
  auto sink = [region, series, keeping](const cam::RawImage& image) {
    if (keeping) series->add(image);
    auto& g = *region;
    if (g.width == 0) choose_uniform_region(image, g);
    if (g.x + g.width > image.width || g.y + g.height > image.height) {
      throw Error(ErrorClass::bad_parameter, "region " + std::to_string(g.x) + "," + std::to_string(g.y) + " " +
                                                 std::to_string(g.width) + "×" + std::to_string(g.height) +
                                                 " leaves the " + std::to_string(image.width) + "×" +
                                                 std::to_string(image.height) + " image");
    }
    g.mosaic = image.cfa.is_mosaic();
    std::size_t pw = g.width / 2, ph = g.height / 2;
    std::vector<float> plane[3];
    for (auto& p : plane) p.assign(pw * ph, 0.f);
    for (std::size_t yy = 0; yy < ph * 2; ++yy) {
      for (std::size_t xx = 0; xx < pw * 2; ++xx) {
        std::size_t x = g.x + xx, y = g.y + yy;
        int channel = 1;
        if (g.mosaic) {
          auto c = image.cfa.at(y, x);
          if (c == cam::CfaColor::green && ((y & 1U) != (g.y & 1U))) continue;  // second green: skip
          channel = c == cam::CfaColor::red ? 0 : c == cam::CfaColor::blue ? 2
                                                                           : 1;
        } else if (((xx | yy) & 1U) != 0) {
          continue;  // monochrome: one sample per 2×2 cell keeps the planes the same size
        }
        plane[channel][(yy / 2) * pw + xx / 2] = static_cast<float>(image.at(x, y)) - image.black_at(x, y);
      }
    }
    for (int c = 0; c < 3; ++c) {
      if (g.mosaic || c == 1) g.planes[c].push_back(std::move(plane[c]));
    }
  };
  cam::CaptureReport report =
      co_await cam::async_capture(camera, static_cast<std::size_t>(frames), sink, boost::asio::use_awaitable);
  if (!report.complete()) {
    if (report.error) throw *report.error;
    throw Error(ErrorClass::hardware_fail, "the camera delivered " + std::to_string(report.delivered) + " of " +
                                               std::to_string(report.requested) + " frames");
  }

  detail::KeepRequest kept{keep, "", series.get(), {}, {}};
  for (const auto& f : report.saved_files) {
    if (detail::is_raw_file(f)) kept.raw_files.push_back(f);
  }
  json blobs = json::array();
  if (keeping) blobs = co_await detail::keep_on_worker(keeper, std::move(kept));

  std::vector<std::size_t> subsets;
  for (std::size_t n : analysis::kTable2Subsets) {
    if (n <= static_cast<std::size_t>(frames)) subsets.push_back(n);
  }
  if (subsets.empty() || subsets.back() != static_cast<std::size_t>(frames)) subsets.push_back(static_cast<std::size_t>(frames));
  std::size_t pw = region->width / 2, ph = region->height / 2;
  analysis::Rect whole{0, 0, pw, ph};
  json rows = json::array();
  for (int c = 0; c < 3; ++c) {
    if (region->planes[c].empty()) continue;
    std::vector<analysis::ImageView> views;
    for (const auto& p : region->planes[c]) views.push_back(analysis::ImageView{p.data(), pw, ph, pw});
    auto table = analysis::noise_vs_averaging(views, std::span<const analysis::Rect>(&whole, 1), subsets);
    for (const auto& row : table) {
      rows.push_back({{"frames", row.frames}, {"channel", kChannelNames[c]}, {"stdev", row.summary.median}});
    }
  }
  co_return json{{"frames", frames},
                 {"region", {region->x, region->y, region->width, region->height}},
                 {"rows", rows},
                 {"instrument", instrument.id()},
                 {"unit", "DN above black"},
                 {"blobs", blobs}};
}

}  // namespace colorlab::campaigns
