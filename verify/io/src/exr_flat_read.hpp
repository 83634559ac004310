#pragma once
// The common renderer's OpenEXR — flat scanlines, uncompressed or ZIP/ZIPS, float channels — decoded here rather
// than through OpenEXR's frame buffer (docs/PERFORMANCE.md "Verifying a rendering"): OpenEXR 3.1 copies a ZIP
// chunk into the frame buffer through one out-of-line XDR read per value, which took as long as inflating it.
#include <ImfHeader.h>
#include <ImfInputPart.h>

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace colorlab::verify::detail {

// Reads the data window of `channels` into OpenEXR's slice convention: absolute pixel (x, y)'s channel c at
// base + x·xs + y·ys + c·sizeof(float). Returns false, having read nothing, for any file it does not handle (tiled,
// another compression, a wanted channel that is not FLOAT, a subsampled channel); the caller then asks OpenEXR.
// Chunks are inflated (libdeflate) on a pool bounded by the machine's cores; a malformed chunk is Error(bad_data).
bool read_flat_float_scanlines(Imf::InputPart& in, const Imf::Header& header, const std::vector<std::string>& channels,
                               char* base, std::size_t xs, std::size_t ys, const std::filesystem::path& file);

}  // namespace colorlab::verify::detail
