#pragma once
// Internals of the chart locator, one file per step (see colorlab/analysis/chart_locate.hpp for the whole).
#include <array>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "colorlab/analysis/chart_locate.hpp"

namespace colorlab::analysis::chart_detail {

// ---- working_image.cpp: the photograph as an 8-bit grey image of at most ~1800 px, for finding the patches ----
struct WorkingImage {
  cv::Mat grey;      // CV_8UC1
  double scale = 1;  // working = (full + 0.5) · scale − 0.5
  cv::Point2d to_full(cv::Point2d p) const { return {(p.x + 0.5) / scale - 0.5, (p.y + 0.5) / scale - 0.5}; }
  cv::Point2d to_working(cv::Point2d p) const { return {(p.x + 0.5) * scale - 0.5, (p.y + 0.5) * scale - 0.5}; }
};
cv::Mat wrap(const PhotoView& photo);  // no copy
void check_photo(const PhotoView& photo);
WorkingImage make_working_image(const PhotoView& photo);

// ---- patch_quads.cpp: near-square regions that may be patches, in full-resolution pixels ----
struct Quad {
  std::array<cv::Point2d, 4> corners;  // convex, in contour order
  cv::Point2d centre;                  // region centroid
  double side = 0;                     // mean side length
};
std::vector<Quad> find_patch_quads(const WorkingImage& work);

// ---- lens.cpp: between distorted (photographed) and undistorted pixels ----
std::vector<cv::Point2d> undistort_points(const std::vector<cv::Point2d>& pts, const std::optional<LensCalibration>& lens);
cv::Point2d distort_point(cv::Point2d undistorted, const std::optional<LensCalibration>& lens);

// ---- homography.cpp: small helpers on 3×3 homographies ----
cv::Point2d apply(const cv::Matx33d& h, cv::Point2d p);
std::array<double, 9> to_array(const cv::Matx33d& h);
cv::Matx33d from_array(const std::array<double, 9>& a);
// Image point (distorted) of a grid point.
inline cv::Point2d grid_to_image(const cv::Matx33d& h, cv::Point2d g, const std::optional<LensCalibration>& lens) {
  return distort_point(apply(h, g), lens);
}

// ---- lattice.cpp: quads on an integer lattice (i, j) and the homography lattice → undistorted image ----
struct Lattice {
  std::map<std::pair<int, int>, int> cells;  // (i, j) → quad index
  cv::Matx33d to_image;                      // (i, j) → undistorted pixels
  int imin = 0, imax = -1, jmin = 0, jmax = -1;
  double pitch_px = 0;  // median distance between neighbouring centres
  double rms_px = 0;    // detected centres vs the fit
  int ni() const { return imax - imin + 1; }
  int nj() const { return jmax - jmin + 1; }
};
// nullopt when fewer than `min_cells` quads form a lattice.
std::optional<Lattice> build_lattice(const std::vector<Quad>& quads, const std::vector<cv::Point2d>& centres,
                                     int min_cells);
// Re-assigns every quad whose centre lies within a third of a pitch of a predicted cell in the given range and
// refits. Keeps the range.
void refine_lattice(Lattice& lattice, const std::vector<cv::Point2d>& centres, int imin, int imax, int jmin, int jmax);

// ---- orientation.cpp: which way up the chart lies on the lattice ----
struct OrientationChoice {
  int quarter_turns = 0;  // of the chart grid on the lattice
  cv::Matx33d grid_to_lattice;
  double score = 0, margin = 0;
  bool scored = false;  // false: no expected luminances to score with
};
// Placements of the layout on the lattice's extent (two when it fits, none when it does not).
std::vector<OrientationChoice> placements(const ChartLayout& layout, const Lattice& lattice);
// Scores each placement by log_agreement() + log_correlation() (0..2) of measured and expected luminance; sorts best first.
void score_placements(std::vector<OrientationChoice>& choices, const ChartLayout& layout,
                      const std::vector<double>& expected, const WorkingImage& work, const Lattice& lattice,
                      const std::optional<LensCalibration>& lens);
double spearman(const std::vector<double>& a, const std::vector<double>& b);
// Fraction of patches whose log measured luminance (8-bit working grey) lies within a factor 1.8 of a straight
// line in log expected luminance: 1 when the chart is the right way up. Turned half a turn, 12 of the SG's 44
// border neutrals swap between white, grey and black (ratios 5 and 24) and fall off the line.
double log_agreement(const std::vector<double>& got, const std::vector<double>& want);
// Pearson correlation of the same logs (separates the CC24's many levels better).
double log_correlation(const std::vector<double>& got, const std::vector<double>& want);
// Mean grey of the working image around a full-resolution point (a third of a patch across).
double working_luminance(const WorkingImage& work, cv::Point2d full, double radius_full);

// ---- centroid_refit.cpp: a region's centroid is not its centre once perspective shrinks the far side ----
// Refits grid → undistorted image to the detected patches' centroids, each corrected by the offset between the
// centroid of the patch as the current fit projects it and its projected centre. Returns the fit and its rms.
std::optional<std::pair<cv::Matx33d, double>> refit_centroids(const ChartLayout& layout, const cv::Matx33d& h,
                                                              const std::vector<bool>& detected,
                                                              const std::vector<cv::Point2d>& observed);

// ---- self_check.cpp ----
SelfCheck check_repeated_neutrals(const ChartLayout& layout, const std::vector<std::vector<int>>& groups,
                                  const std::vector<ChartPatchSample>& patches, double black, double tolerance);
SelfCheck check_neutral_ramp(const ChartLayout& layout, const std::vector<ChartPatchSample>& patches, double black);

}  // namespace colorlab::analysis::chart_detail
