#pragma once
// The simulated DSLR's raw mosaic as the chart locator reads it (12-bit RGGB, the frame's own black level).
#include "colorlab/analysis/chart_photo.hpp"
#include "colorlab/analysis/patch_stats.hpp"
#include "colorlab/sim/camera/raw_frame.hpp"

namespace colorlab::verify::testing {

inline analysis::PhotoView raw_view(const sim::camera::RawFrame& f) {
  analysis::PhotoView v;
  v.data = f.pixels.data();
  v.width = f.width;
  v.height = f.height;
  v.channels = 1;
  v.type = analysis::SampleType::u16;
  v.bit_depth = 12;
  v.black_level = f.black_level;
  v.cfa = analysis::CfaPattern::rggb;
  return v;
}

}  // namespace colorlab::verify::testing
