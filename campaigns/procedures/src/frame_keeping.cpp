#include "frame_keeping.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstring>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/thread_pool.hpp>
#include <boost/asio/use_awaitable.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/thread_priority.hpp"

namespace colorlab::campaigns::detail {

namespace asio = boost::asio;
namespace cam = drivers::camera;
using nlohmann::json;

// The arrays are written as the machine holds them and described as little-endian.
static_assert(std::endian::native == std::endian::little, "blob arrays are written as little-endian");

namespace {

// One thread for writing kept frames: an fsync of a large file must not hold the daemon's io thread.
asio::thread_pool& keeping_worker() {
  static asio::thread_pool pool(1);
  // Hashing and writing large frames is heavy: below the daemon's answering threads (core/thread_priority.hpp).
  // Posted first, so the thread is lowered before its first frame.
  static const bool lowered = (asio::post(pool, [] { core::become_heavy_thread("keeping"); }), true);
  (void)lowered;
  return pool;
}

json array_meta(const SeriesFrames& s, const std::string& dtype) {
  return json{{"dtype", dtype},
              {"shape", {s.height, s.width}},
              {"cfa", s.cfa},
              {"black_level", s.black[0]},
              {"black_levels", s.black},
              {"white_level", s.white},
              {"unit", "DN"}};
}

template <class T>
std::span<const std::uint8_t> as_bytes(const std::vector<T>& v) {
  return {reinterpret_cast<const std::uint8_t*>(v.data()), v.size() * sizeof(T)};
}

}  // namespace

bool KeepOptions::wants(const std::string& kind) const { return std::find(kinds.begin(), kinds.end(), kind) != kinds.end(); }

KeepOptions parse_keep(const json& options, const std::string& call, const std::vector<std::string>& allowed,
                       const std::vector<std::string>& defaults) {
  KeepOptions k;
  if (!options.is_object() || !options.contains("keep")) {
    k.kinds = defaults;
    return k;
  }
  const json& keep = options["keep"];
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
  // An empty Lua table arrives as an empty array or object: keep nothing.
  if (!keep.is_array() && !(keep.is_object() && keep.empty())) {
    throw Error(ErrorClass::bad_parameter, "lab." + call + ": keep must be a list of " + list);
  }
  for (const auto& v : keep) {
    if (!v.is_string() || std::find(allowed.begin(), allowed.end(), v.get<std::string>()) == allowed.end()) {
      throw Error(ErrorClass::bad_parameter, "lab." + call + ": keep names " + list + ", got " + v.dump());
    }
    if (!k.wants(v.get<std::string>())) k.kinds.push_back(v.get<std::string>());
  }
  return k;
}

void SeriesFrames::add(const cam::RawImage& image) {
  if (frames == 0) {
    width = image.width;
    height = image.height;
    sum.assign(width * height, 0);
    cfa = image.cfa.is_mosaic() ? image.cfa.name() : "mono";
    black = image.black_level;
    white = image.white_level;
    if (keep_first) first.resize(width * height);
  } else if (image.width != width || image.height != height) {
    throw Error(ErrorClass::bad_data, "frame " + std::to_string(image.frame_index) + " is " + std::to_string(image.width) + "×" +
                                          std::to_string(image.height) + ", the first was " + std::to_string(width) + "×" +
                                          std::to_string(height));
  }
  for (std::size_t y = 0; y < height; ++y) {
    auto row = image.row(y);
    auto* s = sum.data() + y * width;
    for (std::size_t x = 0; x < width; ++x) s[x] += row[x];
    if (frames == 0 && keep_first) std::memcpy(first.data() + y * width, row.data(), width * sizeof(std::uint16_t));
  }
  ++frames;
}

bool is_raw_file(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".dng" || ext == ".cr2" || ext == ".nef" || ext == ".arw" || ext == ".raw";
}

json keep_now(FrameKeeper& keeper, const KeepRequest& r) {
  json out = json::array();
  std::optional<KeptBlob> average, raw;
  const SeriesFrames* s = r.series;
  if (s && s->frames > 0 && r.keep.wants("average")) {
    // The mean in DN as captured (black not taken off: the meta says where it is).
    std::vector<float> mean(s->sum.size());
    const double n = s->frames;
    for (std::size_t i = 0; i < mean.size(); ++i) mean[i] = static_cast<float>(s->sum[i] / n);
    json meta = array_meta(*s, "<f4");
    meta["frames"] = s->frames;
    average = keeper.keep_bytes(r.prefix + "average", "average", kArrayMediaType, meta, as_bytes(mean));
    out.push_back(blob_json(*average));
  }
  if (r.keep.wants("raw")) {
    if (!r.raw_files.empty()) {
      const auto& f = r.raw_files.front();
      raw = keeper.keep_file(r.prefix + f.filename().string(), "raw", media_type_of(f), json{{"frame", 1}, {"file_name", f.filename().string()}}, f);
      out.push_back(blob_json(*raw));
    } else if (s && !s->first.empty()) {
      json meta = array_meta(*s, "<u2");
      meta["frame"] = 1;
      raw = keeper.keep_bytes(r.prefix + "first", "raw", kArrayMediaType, meta, as_bytes(s->first));
      out.push_back(blob_json(*raw));
    }
  }
  for (const auto& [format, file] : r.processed) {
    if (!r.keep.wants(format)) continue;
    out.push_back(blob_json(keeper.keep_file(format + "/" + file.filename().string(), format, media_type_of(file),
                                             json{{"frame", 1}, {"file_name", file.filename().string()}}, file)));
  }
  if (r.keep.wants("preview") && (average || raw)) {
    out.push_back(blob_json(keeper.keep_preview(r.prefix + (average ? "average.png" : "first.png"), average ? *average : *raw)));
  }
  return out;
}

asio::awaitable<json> keep_on_worker(FrameKeeper* keeper, KeepRequest request) {
  if (!keeper || !request.keep.any()) co_return json::array();
  auto work = [](FrameKeeper* k, KeepRequest r) -> asio::awaitable<json> { co_return keep_now(*k, r); };
  co_return co_await asio::co_spawn(keeping_worker(), work(keeper, std::move(request)), asio::use_awaitable);
}

}  // namespace colorlab::campaigns::detail
