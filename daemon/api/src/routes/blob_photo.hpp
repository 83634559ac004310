#pragma once
// A stored blob read as the chart locator's photograph: the camera's own TIFF/JPEG/PNG as they are, a raw file
// (DNG, CR2, NEF) as its CFA mosaic through LibRaw — the same decoder the campaigns use —, and colorlab's arrays
// (the averaged frame) as 16-bit samples scaled by a power of two so an average keeps its sub-count precision.
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "colorlab/analysis/chart_photo.hpp"

namespace colorlab::daemon {

struct BlobPhoto {
  analysis::Photo photo;
  std::optional<analysis::CfaPattern> cfa;  // a raw mosaic: sampled per CFA colour
  double black_level = 0;                   // in the blob's own counts (a mosaic's; 0 for processed images)
  int bits = 0;                             // significant bits of the blob's counts (0: 8 or 16 from the type)
  double scale = 1;                         // photo samples = blob counts × scale (arrays only)

  analysis::PhotoView view() const;  // black level and bits in the photo's (scaled) counts
};

// Error{unsupported} for a media type that is no photograph, Error{bad_data} for one that cannot be decoded.
BlobPhoto read_blob_photo(const std::filesystem::path& file, const std::string& media_type, const nlohmann::json& meta);

}  // namespace colorlab::daemon
