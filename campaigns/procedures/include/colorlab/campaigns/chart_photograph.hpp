#pragma once
// Chapter 7's photographs as one lab call, lab.camera.photograph_chart: N frames of the chart in the
// cabinet, the raw averaged in the camera's frame pipeline and the camera's own processed files
// (16-bit and 8-bit TIFF, JPEG) averaged per format; in each averaged photograph the chart is
// located with colorlab_chart_locate (the code of `colorlab analyze locate-chart`) and every patch
// sampled with the robust value (per CFA colour on the raw, before demosaicing). Decoding the
// processed files and locating run on a worker thread, so the daemon's io thread keeps answering.
// Only patch values come back, small enough to journal.
#include <memory>

#include <boost/asio/awaitable.hpp>
#include <nlohmann/json.hpp>

#include "colorlab/campaigns/frame_keeper.hpp"

namespace colorlab::drivers::camera {
class CameraInstrument;
}

namespace colorlab::campaigns {

// options: {frames = 25 (1..256), chart = "sg" | "cc24", formats = {"raw", "tiff16", "tiff8", "jpeg"},
// sample_fraction = 0.6, min_confidence = 0.6, camera = id (used by the caller to choose),
// keep = {"average", "raw", "preview"} (of average, raw, tiff16, tiff8, jpeg, preview: what goes into
// the keeper once every photograph was sampled — the averaged raw as a float array, the first raw as
// captured, the first frame's processed files, a PNG preview of the average), centres = false (true: each
// format's observed_px, the detected patches' centroids as photographed, for a lens calibration)}.
// Returns {instrument, chart, frames, formats = {<format> = {confidence, rotation_deg, corners,
// patches_detected, reprojection_rms_px, check, ids, values = [[r, g, b], …], …}}, blobs = [kept blob
// references]}.
// Throws Error(unsupported) when the camera cannot deliver a format, the locator's Error when a
// photograph does not show the chart clearly.
boost::asio::awaitable<nlohmann::json> photograph_chart(drivers::camera::CameraInstrument& camera,
                                                        const nlohmann::json& options, FrameKeeper* keeper = nullptr);

}  // namespace colorlab::campaigns
