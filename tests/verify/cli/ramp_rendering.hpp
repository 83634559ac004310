#pragma once
// An XYZ rendering whose luminance ramps across the frame, for the CLI tests that ask where the floor was placed:
// the comparisons' verdicts do not matter there, only where the regions were sampled, which the ramp turns into the
// rendered value (`rendered`, in the order of the result's comparisons).
#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/verify/rendering.hpp"

namespace colorlab::verify::cli_testing {

inline Rendering ramp(int width, int height) {
  Rendering r;
  r.width = width, r.height = height;
  r.encoding = Encoding::xyz;
  r.units = "cd/m^2";
  r.pixels.resize(static_cast<std::size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float Y = 50.0f + 0.05f * static_cast<float>(x) + 0.03f * static_cast<float>(y);
      float* p = r.pixels.data() + (static_cast<std::size_t>(y) * width + x) * 3;
      p[0] = Y * 0.95047f, p[1] = Y, p[2] = Y * 1.08883f;
    }
  return r;
}

inline std::vector<double> rendered(const nlohmann::json& result) {
  std::vector<double> out;
  for (const auto& c : result["comparisons"]) out.push_back(c["rendered"][0].get<double>());
  return out;
}

}  // namespace colorlab::verify::cli_testing
