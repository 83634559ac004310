#include "colorlab/campaigns/chart_photograph.hpp"

#include <algorithm>
#include <limits>
#include <map>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/thread_pool.hpp>
#include <boost/asio/use_awaitable.hpp>

#include "chart_sampling.hpp"
#include "frame_keeping.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/core/thread_priority.hpp"
#include "colorlab/drivers/camera/asio_camera.hpp"
#include "colorlab/drivers/camera/camera_instrument.hpp"

namespace colorlab::campaigns {

namespace asio = boost::asio;
namespace cam = drivers::camera;
namespace ca = analysis;
using nlohmann::json;

namespace {

const std::vector<std::string> kFormats = {"raw", "tiff16", "tiff8", "jpeg"};

struct PhotographOptions {
  int frames = 25;
  std::vector<std::string> formats = kFormats;
  detail::SamplingOptions sampling;
  detail::KeepOptions keep;
};

PhotographOptions parse(const json& o) {
  PhotographOptions p;
  auto bad = [](const std::string& what) { return Error(ErrorClass::bad_parameter, "lab.camera.photograph_chart: " + what); };
  if (!o.is_object() && !(o.is_array() && o.empty())) throw bad("takes a table {frames=, chart=, formats=, camera=, reference=}");
  // What a lab wants back of a photograph: the averaged raw and one raw as captured (a preview to glance at).
  p.keep = detail::parse_keep(o, "camera.photograph_chart", {"average", "raw", "tiff16", "tiff8", "jpeg", "preview"},
                              {"average", "raw", "preview"});
  if (!o.is_object()) return p;
  if (o.contains("frames")) {
    if (!o["frames"].is_number_integer() || o["frames"].get<int>() < 1 || o["frames"].get<int>() > 256) throw bad("frames must be an integer from 1 to 256");
    p.frames = o["frames"].get<int>();
  }
  if (o.contains("chart")) {
    if (!o["chart"].is_string()) throw bad("chart must be \"sg\" or \"cc24\"");
    p.sampling.chart = ca::chart_type_from_string(o["chart"].get<std::string>());
  }
  if (o.contains("formats")) {
    p.formats.clear();
    for (const auto& f : o["formats"]) {
      if (!f.is_string() || std::find(kFormats.begin(), kFormats.end(), f.get<std::string>()) == kFormats.end()) {
        throw bad("formats must name raw, tiff16, tiff8 or jpeg, got " + f.dump());
      }
      if (std::find(p.formats.begin(), p.formats.end(), f.get<std::string>()) == p.formats.end()) p.formats.push_back(f);
    }
    if (p.formats.empty()) throw bad("formats must name at least one of raw, tiff16, tiff8, jpeg");
  }
  auto fraction = [&](const char* key, double& out) {
    if (!o.contains(key)) return;
    if (!o[key].is_number() || !(o[key].get<double>() > 0 && o[key].get<double>() <= 1)) throw bad(std::string(key) + " must be a number in (0, 1]");
    out = o[key].get<double>();
  };
  if (o.contains("corners")) {
    // {raw = {x1, y1, …, x4, y4}, jpeg = {…}}: the operator's corners per format; an empty list = locate it alone.
    const json& c = o["corners"];
    if (!c.is_object() && !(c.is_array() && c.empty())) throw bad("corners must be a table {<format> = {x1, y1, x2, y2, x3, y3, x4, y4}}");
    if (c.is_object()) {
      for (const auto& [format, v] : c.items()) {
        if (std::find(kFormats.begin(), kFormats.end(), format) == kFormats.end()) throw bad("corners names no format '" + format + "'");
        if (v.is_array() && v.empty()) continue;
        if (!v.is_array() || v.size() != 8 || !std::all_of(v.begin(), v.end(), [](const json& x) { return x.is_number(); }))
          throw bad("corners." + format + " must be 8 numbers x1, y1, …, x4, y4 (or empty)");
        std::array<ca::Point2, 4> corners{};
        for (std::size_t i = 0; i < 4; ++i) corners[i] = {v[2 * i].get<double>(), v[2 * i + 1].get<double>()};
        p.sampling.corners[format] = corners;
      }
    }
  }
  if (o.contains("on_refusal")) {
    if (o["on_refusal"] != "error" && o["on_refusal"] != "return") throw bad("on_refusal must be \"error\" or \"return\"");
    p.sampling.return_refusals = o["on_refusal"] == "return";
  }
  if (o.contains("centres")) {
    if (!o["centres"].is_boolean()) throw bad("centres must be true or false");
    p.sampling.centres = o["centres"].get<bool>();
  }
  fraction("sample_fraction", p.sampling.sample_fraction);
  fraction("min_confidence", p.sampling.min_confidence);
  if (o.contains("reference")) {
    // lab.runs.chart_reference's table: each patch's Y, in the layout's order (unknown patches stay NaN).
    const json& r = o["reference"];
    if (!r.is_object() || !r.contains("ids") || !r.contains("XYZ") || !r["ids"].is_array() || !r["XYZ"].is_array() ||
        r["ids"].size() != r["XYZ"].size()) {
      throw bad("reference must be lab.runs.chart_reference's table {ids = {...}, XYZ = {{X, Y, Z}, ...}}");
    }
    const ca::ChartLayout& layout = ca::chart_layout(p.sampling.chart);
    ca::ChartReference ref;
    ref.luminance.assign(static_cast<std::size_t>(layout.size()), std::numeric_limits<double>::quiet_NaN());
    std::size_t known = 0;
    for (std::size_t i = 0; i < r["ids"].size(); ++i) {
      const json& xyz = r["XYZ"][i];
      if (!r["ids"][i].is_string() || !xyz.is_array() || xyz.size() != 3 || !xyz[1].is_number()) throw bad("reference patch " + std::to_string(i + 1) + " has no id and XYZ");
      const auto it = std::find(layout.ids.begin(), layout.ids.end(), r["ids"][i].get<std::string>());
      if (it == layout.ids.end()) continue;
      ref.luminance[static_cast<std::size_t>(it - layout.ids.begin())] = xyz[1].get<double>();
      ++known;
    }
    if (known == 0) throw bad("the reference names none of the " + layout.name + "'s patches: is it a read of another chart?");
    p.sampling.reference = std::move(ref);
  }
  return p;
}

bool wants(const PhotographOptions& p, const std::string& format) {
  return std::find(p.formats.begin(), p.formats.end(), format) != p.formats.end();
}

ca::CfaPattern cfa_of(const cam::CfaPattern& c, const std::string& camera) {
  using C = cam::CfaColor;
  if (c.cell[0][0] == C::red && c.cell[1][1] == C::blue) return ca::CfaPattern::rggb;
  if (c.cell[0][0] == C::blue && c.cell[1][1] == C::red) return ca::CfaPattern::bggr;
  if (c.cell[0][1] == C::red && c.cell[1][0] == C::blue) return ca::CfaPattern::grbg;
  if (c.cell[0][1] == C::blue && c.cell[1][0] == C::red) return ca::CfaPattern::gbrg;
  throw Error(ErrorClass::unsupported, camera + " delivers a " + c.name() + " sensor, not a Bayer mosaic",
              "a chart characterization needs colour: use a colour camera");
}

// The raw frames' sum over the visible area, filled on the camera's decode thread; read on the io
// thread only after the series has ended.
struct RawSum {
  std::vector<std::uint32_t> sum;
  int width = 0, height = 0, frames = 0;
  cam::CfaPattern cfa;
  double black = 0;
  int bits = 16;
  std::array<std::uint16_t, 4> blacks{};
  std::uint16_t white = 0;
};

int significant_bits(const cam::RawImage& image) {
  int bits = 1;
  while (bits < 16 && (1U << bits) <= image.white_level) ++bits;
  return image.white_level > 0 ? bits : static_cast<int>(image.bits_per_sample);
}

// The sidecars of a series by format: a real DSLR's download has only JPEGs; the simulated one
// writes 8- and 16-bit TIFFs as well, told apart by their sample type, not by a naming habit.
std::map<std::string, detail::AveragedPhoto> average_sidecars(const std::vector<std::filesystem::path>& files,
                                                              const PhotographOptions& p) {
  std::map<std::string, std::vector<std::filesystem::path>> by_format;
  for (const auto& f : files) {
    std::string ext = f.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".jpg" || ext == ".jpeg") by_format["jpeg"].push_back(f);
    if (ext == ".tif" || ext == ".tiff") by_format["tiff"].push_back(f);
  }
  std::map<std::string, detail::AveragedPhoto> out;
  if (wants(p, "jpeg") && !by_format["jpeg"].empty()) out["jpeg"] = detail::average_files("jpeg", by_format["jpeg"]);
  if ((wants(p, "tiff8") || wants(p, "tiff16")) && !by_format["tiff"].empty()) {
    auto tiffs = detail::average_tiffs(by_format["tiff"]);
    for (auto& [format, photo] : tiffs) {
      if (wants(p, format)) out[format] = std::move(photo);
    }
  }
  return out;
}

// Runs on the worker pool: average the processed files, locate and sample every photograph.
// Returns {formats, blobs}: the frames are kept only once every photograph was located and sampled.
asio::awaitable<json> sample_all(std::shared_ptr<RawSum> raw, std::vector<std::filesystem::path> sidecars,
                                 std::vector<std::filesystem::path> raw_files, PhotographOptions p, std::string camera_name,
                                 FrameKeeper* keeper) {
  json formats = json::object();
  bool keeping = keeper && p.keep.any();
  if (wants(p, "raw")) {
    detail::AveragedPhoto a;
    a.format = "raw";
    a.frames = raw->frames;
    a.bits = raw->bits;
    a.scale = std::ldexp(1.0, 16 - raw->bits);
    a.black_level = raw->black;
    a.cfa = cfa_of(raw->cfa, camera_name);
    a.photo.width = raw->width;
    a.photo.height = raw->height;
    a.photo.channels = 1;
    a.photo.type = ca::SampleType::u16;
    a.photo.bytes.resize(raw->sum.size() * sizeof(std::uint16_t));
    auto* dst = reinterpret_cast<std::uint16_t*>(a.photo.bytes.data());
    const double k = a.scale / raw->frames;
    for (std::size_t i = 0; i < raw->sum.size(); ++i) dst[i] = static_cast<std::uint16_t>(std::min(65535.0, std::round(raw->sum[i] * k)));
    formats["raw"] = detail::locate_and_sample(a, p.sampling);
    if (!keeping && !formats["raw"].contains("refused")) raw->sum = {};
  }
  auto processed = average_sidecars(sidecars, p);
  for (const auto& format : p.formats) {
    if (format == "raw") continue;
    auto it = processed.find(format);
    if (it == processed.end()) {
      throw Error(ErrorClass::hardware_fail, camera_name + " delivered no " + format + " files with its raws",
                  "check the camera's image format (raw+jpeg+tiff), or ask only for the formats it writes");
    }
    formats[format] = detail::locate_and_sample(it->second, p.sampling);
  }
  // A refused photograph is kept whatever `keep` says — the raw as the average the locator saw, a processed format
  // as its first file —, so the operator can find its corners in it (POST /v1/blobs/{sha256}/locate-chart).
  for (const auto& [format, f] : formats.items()) {
    if (!f.contains("refused")) continue;
    const std::string kind = format == "raw" ? "average" : format;
    if (!p.keep.wants(kind)) p.keep.kinds.push_back(kind);
  }
  keeping = keeper && p.keep.any();
  json blobs = json::array();
  if (keeping) {
    detail::SeriesFrames series;
    if (wants(p, "raw") && raw->frames > 0) {
      series.sum = std::move(raw->sum);
      series.width = static_cast<std::size_t>(raw->width);
      series.height = static_cast<std::size_t>(raw->height);
      series.frames = raw->frames;
      series.cfa = raw->cfa.is_mosaic() ? raw->cfa.name() : "mono";
      series.black = raw->blacks;
      series.white = raw->white;
    }
    detail::KeepRequest request{p.keep, "raw/", &series, {}, {}};
    if (wants(p, "raw") && !raw_files.empty()) request.raw_files.push_back(raw_files.front());
    for (const auto& [format, photo] : processed) {
      if (!photo.files.empty()) request.processed.emplace_back(format, photo.files.front());
    }
    blobs = detail::keep_now(*keeper, request);
  }
  co_return json{{"formats", formats}, {"blobs", blobs}};
}

// One thread for chart work: a second campaign's photographs wait rather than take both cores
// from the daemon and the simulated lab. Joined at exit.
asio::thread_pool& chart_worker() {
  static asio::thread_pool pool(1);
  // Averaging, locating and sampling are heavy: below the daemon's answering threads (core/thread_priority.hpp).
  // Posted first, so the thread is lowered before its first job.
  static const bool lowered = (asio::post(pool, [] { core::become_heavy_thread("chart"); }), true);
  (void)lowered;
  return pool;
}

}  // namespace

asio::awaitable<json> photograph_chart(cam::CameraInstrument& instrument, const json& options, FrameKeeper* keeper) {
  const PhotographOptions p = parse(options);
  auto& camera = instrument.camera();
  const bool tiff = wants(p, "tiff8") || wants(p, "tiff16");
  const bool processed = tiff || wants(p, "jpeg");
  const auto want = tiff ? cam::ImageFormat::raw_jpeg_tiff : processed ? cam::ImageFormat::raw_and_jpeg
                                                                       : cam::ImageFormat::raw;
  const auto offered = camera.limits().image_formats;
  const auto before = camera.settings().image_format;
  if (processed && std::find(offered.begin(), offered.end(), want) == offered.end()) {
    throw Error(ErrorClass::unsupported,
                camera.name() + " cannot deliver " + std::string(cam::to_string(want)) + " (chapter 7's processed test cases)",
                "ask for formats = {\"raw\"} from this camera, or convert its raws with a raw converter on the bench");
  }
  auto set_format = [&](cam::ImageFormat f) -> asio::awaitable<void> {
    cam::CameraSettings s;
    s.image_format = f;
    auto error = co_await cam::async_configure(camera, s, asio::use_awaitable);
    if (error) throw *error;
  };
  if (!offered.empty() && before != want) co_await set_format(want);

  auto raw = std::make_shared<RawSum>();
  // Runs on the camera's decode thread, frame by frame: the raw series never exists in memory.
  auto sink = [raw](const cam::RawImage& image) {
    auto& r = *raw;
    if (r.sum.empty()) {
      r.width = static_cast<int>(image.width);
      r.height = static_cast<int>(image.height);
      r.sum.assign(image.width * image.height, 0);
      r.cfa = image.cfa;
      r.black = image.black_level[0];
      r.blacks = image.black_level;
      r.white = image.white_level;
      r.bits = significant_bits(image);
    } else if (static_cast<int>(image.width) != r.width || static_cast<int>(image.height) != r.height) {
      throw Error(ErrorClass::bad_data, "frame " + std::to_string(image.frame_index) + " is " + std::to_string(image.width) + "×" +
                                            std::to_string(image.height) + ", the first was " + std::to_string(r.width) + "×" +
                                            std::to_string(r.height));
    }
    for (std::size_t y = 0; y < image.height; ++y) {
      auto row = image.row(y);
      auto* s = r.sum.data() + y * image.width;
      for (std::size_t x = 0; x < image.width; ++x) s[x] += row[x];
    }
    ++r.frames;
  };
  cam::CaptureReport report =
      co_await cam::async_capture(camera, static_cast<std::size_t>(p.frames), sink, asio::use_awaitable);
  // Leave the camera as the campaign had it (a later frame-average need not download sidecars).
  if (before && *before != want) co_await set_format(*before);
  if (!report.complete()) {
    if (report.error) throw *report.error;
    throw Error(ErrorClass::hardware_fail, "the camera delivered " + std::to_string(report.delivered) + " of " +
                                               std::to_string(report.requested) + " frames");
  }
  std::vector<std::filesystem::path> sidecars, raw_files;
  for (const auto& f : report.saved_files) {
    if (detail::is_raw_file(f)) raw_files.push_back(f);
    std::string ext = f.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".jpg" || ext == ".jpeg" || ext == ".tif" || ext == ".tiff") sidecars.push_back(f);
  }
  json sampled = co_await asio::co_spawn(chart_worker(),
                                         sample_all(raw, std::move(sidecars), std::move(raw_files), p, camera.name(), keeper),
                                         asio::use_awaitable);
  co_return json{{"instrument", instrument.id()},
                 {"chart", std::string(ca::to_string(p.sampling.chart))},
                 {"frames", p.frames},
                 {"formats", sampled["formats"]},
                 {"blobs", sampled["blobs"]}};
}

}  // namespace colorlab::campaigns
