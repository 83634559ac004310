#pragma once
// Finding a ColorChecker in a photograph and sampling its patches (issue 14; dissertation §6.1.2, fig. 30).
//
// locate_chart: the patches are found as near-square regions (OpenCV adaptive threshold and contours), put on an
// integer lattice by walking from neighbour to neighbour, and a homography from grid units to the (undistorted)
// image is fitted to their centres. Which way up the chart is comes from the patch luminances (the SG's neutral
// border, the CC24's published L*). Each patch is then sampled over a square of `sample_fraction` of its side,
// centred on it and kept inside it, with the robust value of patch_stats.hpp (per CFA colour on a raw mosaic).
// Finally the chart checks itself: the SG's repeated neutrals must agree once a smooth light field is removed, the
// CC24's neutral row must fall from white to black. A result it is unsure of is refused with an Error whose hint
// says what to do — never returned with silently wrong values.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "colorlab/analysis/chart_layout.hpp"
#include "colorlab/analysis/chart_photo.hpp"
#include "colorlab/analysis/patch_stats.hpp"

namespace colorlab::analysis {

struct Point2 {
  double x = 0, y = 0;
};

// OpenCV's pinhole + Brown–Conrady model (as calibrateCamera reports it), in pixels of the photograph.
struct LensCalibration {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
};

// What the photographed chart's patches should look like, when the caller knows better than the layout
// (a simulated chart, a chart measured with the spectrometer).
struct ChartReference {
  // Per patch in layout order, relative; NaN = unknown. Also tells a 2×2 block of patches with no edges of their
  // own (luminance close to the surround's) that reads as expected from a covered chart.
  std::vector<double> luminance;
  std::vector<std::vector<int>> repeated_neutrals;  // replaces the layout's groups when non-empty
};

struct LocateOptions {
  // The operator's four corners (chart_layout.hpp: outer corners of the patch grid, A1's first, clockwise as the
  // chart reads). The order fixes the orientation; the detected patches then refine the fit.
  std::optional<std::array<Point2, 4>> corners;
  std::optional<LensCalibration> lens;
  std::optional<ChartReference> reference;
  double sample_fraction = 0.6;        // sampled square side / patch side, before fitting it inside a tilted patch
  double min_confidence = 0.6;         // below: Error(needs_operator)
  double neutral_tolerance = 0.05;     // largest relative disagreement of a repeated neutral after the field fit
  std::optional<double> robust_k;      // robust band half-width; default 5 counts at 8 bit, scaled by 2^(bits−8)
  const PixelMask* defects = nullptr;  // dead and hot pixels (full frame), excluded from every patch
};

struct ChartPatchSample {
  std::string id;
  Point2 centre;          // image pixels (pixel centres at integers)
  Rect region;            // sampled pixels
  bool detected = false;  // its own square was found (not only predicted by the fit)
  // When detected: the centroid of its own square as photographed (lens distortion not removed) — the point a lens
  // calibration needs (issue 23), where `centre` is the fit's prediction.
  Point2 observed;
  int channels = 1;                 // 1 grey, 3 R, G, B (or the CFA's R, G, B)
  std::array<PatchValue, 3> value;  // robust value per channel
};

struct SelfCheck {
  bool passed = true;
  std::string method;             // "repeated neutrals", "neutral ramp" or "none"
  double worst_disagreement = 0;  // relative, after removing a smooth field (repeated neutrals)
  std::string worst_patch;
  // The light field over the chart from the repeated neutrals: relative change of the brightest group across the
  // chart's width and height (grid axes).
  double gradient_x = 0, gradient_y = 0;
  std::string detail;
};

struct ChartLocation {
  ChartType type = ChartType::sg140;
  std::array<Point2, 4> corners;       // image pixels, reading order (see chart_layout.hpp)
  std::array<double, 9> homography{};  // grid units → undistorted image pixels, row-major
  int rotation_deg = 0;                // how the chart is turned in the image: 0, 90, 180, 270 (clockwise)
  bool from_corners = false;           // the operator's corners were used
  double confidence = 0;               // 0..1
  double orientation_margin = 0;       // best minus second-best orientation score
  double reprojection_rms_px = 0;      // detected centres vs the fit
  int patches_detected = 0;
  std::vector<ChartPatchSample> patches;  // layout order
  SelfCheck check;
  std::vector<std::string> notes;
};

// Throws Error: not_found (no chart), needs_operator (partial, covered, ambiguous or failing its self-check:
// the hint asks for --corners), bad_parameter (options), bad_data (photo).
ChartLocation locate_chart(const PhotoView& photo, ChartType type, const LocateOptions& options = {});

// The sampling step alone, for a known homography (grid units → undistorted pixels).
std::vector<ChartPatchSample> sample_chart(const PhotoView& photo, const ChartLayout& layout,
                                           const std::array<double, 9>& homography, const LocateOptions& options = {});

}  // namespace colorlab::analysis
