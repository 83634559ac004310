#pragma once
// The renderings bench_verify_speed verifies (issue 23 "Speed"): a floor-like field with a render's 1 % per-pixel
// noise (so the files compress like path-traced images) and, square-on in the middle, the embedded simulated lab's
// ColorChecker SG as the simulator lights it under D65 — so the colour half's chart locator has a real chart to
// find, at the size a renderer would show it (about 60 % of the frame's width).
#include "colorlab/verify/rendering.hpp"

namespace colorlab::bench {

// `e`: spectral (36 bands, 380–730 nm, W·m⁻²·sr⁻¹·nm⁻¹), xyz (cd/m²) or rgb (linear Rec. 709, cd/m² for 1,1,1).
verify::Rendering chart_and_floor(verify::Encoding e, int width, int height);

}  // namespace colorlab::bench
