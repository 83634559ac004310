#pragma once
// A PNG preview of any stored frame, for a person glancing at a run: a raw mosaic (a camera's
// raw file or a colorlab array with a CFA) shown per 2×2 cell at half size, a float array scaled so
// its 99.5th percentile is white, 8-bit sRGB gamma; the camera's own TIFF/JPEG as they are. At
// most 1024 pixels on the long side.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace colorlab::daemon {

// Error{unsupported} for a media type it cannot show, Error{bad_data} for a file it cannot read.
std::vector<std::uint8_t> render_preview_png(const std::filesystem::path& file, const std::string& media_type,
                                             const nlohmann::json& meta);

}  // namespace colorlab::daemon
