#pragma once
// What a camera call keeps of its frames (its `keep` option) and the writing of them through the
// lab's FrameKeeper, off the daemon's io thread: the average of the series as a float array, the
// first frame as captured (the camera's raw file, or its counts when the camera delivers pixels),
// the camera's own processed files of the first frame, and a PNG preview of the average.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <boost/asio/awaitable.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/campaigns/frame_keeper.hpp"
#include "colorlab/drivers/camera/raw_image.hpp"

namespace colorlab::campaigns::detail {

struct KeepOptions {
  std::vector<std::string> kinds;  // of "average", "raw", "tiff16", "tiff8", "jpeg", "preview"
  bool wants(const std::string& kind) const;
  bool any() const { return !kinds.empty(); }
};

// options.keep: a list of kinds; absent = `defaults`. Error{bad_parameter} names `call` and the
// kinds it takes (`allowed`).
KeepOptions parse_keep(const nlohmann::json& options, const std::string& call, const std::vector<std::string>& allowed,
                       const std::vector<std::string>& defaults);

// The series' sum over the visible area and the first frame's counts, filled frame by frame on the
// camera's decode thread (never the whole series in memory); read after the series has ended.
struct SeriesFrames {
  std::vector<std::uint32_t> sum;
  std::vector<std::uint16_t> first;  // only when asked for (a camera without raw files)
  std::size_t width = 0, height = 0;
  int frames = 0;
  std::string cfa;  // "RGGB", …, or "mono"
  std::array<std::uint16_t, 4> black{};
  std::uint16_t white = 0;
  bool keep_first = false;

  // Throws Error{bad_data} when a frame's size differs from the first's.
  void add(const drivers::camera::RawImage& image);
};

// What one call keeps, written on a worker thread; returns the blob references for the call's
// result (its "blobs"), or an empty array when there is no keeper or nothing to keep. `prefix` goes
// before each name ("raw/", or "" for a single-format call). `raw_files` and `processed` are the
// first frame's files (processed: format → file).
struct KeepRequest {
  KeepOptions keep;
  std::string prefix;
  const SeriesFrames* series = nullptr;
  std::vector<std::filesystem::path> raw_files;
  std::vector<std::pair<std::string, std::filesystem::path>> processed;
};
nlohmann::json keep_now(FrameKeeper& keeper, const KeepRequest& request);
// The same on the keeping worker, for calls that run on the io thread.
boost::asio::awaitable<nlohmann::json> keep_on_worker(FrameKeeper* keeper, KeepRequest request);

bool is_raw_file(const std::filesystem::path& file);

}  // namespace colorlab::campaigns::detail
