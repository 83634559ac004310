#pragma once
// §6.1.3's image-averaging measurement as one lab call: capture N frames of a region, average the
// first 1, 2, 4, 8, 16, 25 … of them, and return the spatial standard deviation of each average
// per CFA channel (Table 2's layout). The frames never leave the camera's decode thread; only the
// statistics come back, so the result is small enough to journal.
#include <boost/asio/awaitable.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/campaigns/frame_keeper.hpp"

namespace colorlab::drivers::camera {
class Camera;
class CameraInstrument;
}  // namespace colorlab::drivers::camera

namespace colorlab::campaigns {

// options: {frames = 25, region = {x, y, w, h} | {}, keep = {"average", "raw", "preview"}}; returns
// {frames, region = {x, y, w, h}, rows = [{frames, channel, stdev, mean}], unit = "DN above black",
// blobs = [kept blob references]}. `keep` (with a keeper): the series' average as a float array, the
// first frame as captured (its raw file, or its counts as a <u2 array), a PNG preview of the average.
// A camera that offers pixel formats (GenICam) and has none set is asked for its raw Bayer counts (16, else 12 bit,
// else its first format): what averaging and spot values need. Error from the camera otherwise.
boost::asio::awaitable<void> use_sensor_counts(drivers::camera::Camera& camera);

boost::asio::awaitable<nlohmann::json> capture_noise_table(drivers::camera::CameraInstrument& camera,
                                                           const nlohmann::json& options, FrameKeeper* keeper = nullptr);

}  // namespace colorlab::campaigns
