#pragma once
// What the readers and writers of verify/io share; not part of the interface.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "colorlab/verify/rendering.hpp"

namespace colorlab::verify::detail {

// Error(bad_data) naming the file, what is wrong and where.
[[noreturn]] void bad_data(const std::filesystem::path& file, const std::string& what, const std::string& hint = {});

// Rejects NaN and infinities everywhere and negative values where the encoding cannot have them (spectral
// radiance and reflectance, XYZ of physical light); names the first offending pixel and channel and the count.
void check_values(const Rendering& image, const std::filesystem::path& file, const std::vector<std::string>& channel_names);

Rendering read_openexr(const std::filesystem::path& file);
Rendering read_rgbe(const std::filesystem::path& file, std::string_view bytes);
Rendering read_pfm(const std::filesystem::path& file, std::string_view bytes);

// The guard every reader applies before allocating width × height × channels floats from a header.
void check_dimensions(const std::filesystem::path& file, long long width, long long height, long long channels);

}  // namespace colorlab::verify::detail
