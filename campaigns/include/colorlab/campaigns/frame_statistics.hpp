#pragma once
// §6.1.3's image-averaging measurement as one lab call: capture N frames of a region, average the
// first 1, 2, 4, 8, 16, 25 … of them, and return the spatial standard deviation of each average
// per CFA channel (Table 2's layout). The frames never leave the camera's decode thread; only the
// statistics come back, so the result is small enough to journal.
#include <boost/asio/awaitable.hpp>
#include <nlohmann/json.hpp>

namespace colorlab::drivers::camera {
class CameraInstrument;
}

namespace colorlab::campaigns {

// options: {frames = 25, region = {x, y, w, h} | {}}; returns
// {frames, region = {x, y, w, h}, rows = [{frames, channel, stdev, mean}], unit = "DN above black"}.
boost::asio::awaitable<nlohmann::json> capture_noise_table(drivers::camera::CameraInstrument& camera,
                                                           const nlohmann::json& options);

}  // namespace colorlab::campaigns
