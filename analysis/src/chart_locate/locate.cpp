#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "colorlab/core/error.hpp"
#include "internal.hpp"

namespace colorlab::analysis {
namespace {

using namespace chart_detail;

const char* kCornersHint =
    "check that the whole chart is in the frame, lit and in focus; or give its four corners: --corners "
    "x1,y1,x2,y2,x3,y3,x4,y4 (outer corners of the patch grid, the first patch's corner first, clockwise)";

double clamp01(double v) { return std::clamp(v, 0.0, 1.0); }

std::string grid_name(const ChartLayout& L) {
  return L.name + " (" + std::to_string(L.columns) + "×" + std::to_string(L.rows) + " patches)";
}

struct Score {
  double value = 1;
  std::string why;
};

void lower(Score& s, double v, const std::string& why) {
  if (v < s.value) s = {v, why};
}

// Orientation score of a grid placement, for operator corners: given order vs the chart turned half a turn.
double luminance_agreement(const ChartLayout& L, const std::vector<double>& expected, const WorkingImage& work,
                           const cv::Matx33d& h, const std::optional<LensCalibration>& lens, double pitch_px) {
  std::vector<double> got, want;
  for (int k = 0; k < L.size(); ++k) {
    if (!std::isfinite(expected[static_cast<std::size_t>(k)])) continue;
    got.push_back(working_luminance(work, grid_to_image(h, {L.centre_x(k), L.centre_y(k)}, lens), pitch_px * L.patch_size / 6));
    want.push_back(expected[static_cast<std::size_t>(k)]);
  }
  return log_agreement(got, want) + log_correlation(got, want);
}

// Every 2×2 block of patches none of which shows its own edges (layout indices): something may cover the chart there.
std::vector<std::array<int, 4>> undetected_blocks(const ChartLayout& L, const std::vector<bool>& detected) {
  std::vector<std::array<int, 4>> out;
  for (int c = 0; c + 1 < L.columns; ++c)
    for (int r = 0; r + 1 < L.rows; ++r) {
      std::array<int, 4> block{};
      int n = 0;
      for (int dc = 0; dc < 2; ++dc)
        for (int dr = 0; dr < 2; ++dr) {
          const int k = *L.index_at(c + dc, r + dr);
          if (!detected[static_cast<std::size_t>(k)]) block[static_cast<std::size_t>(n++)] = k;
        }
      if (n == 4) out.push_back(block);
    }
  return out;
}

// Whether an edgeless block is the chart itself, not a cover. Patches whose luminance is close to the surround's
// show no luminance edge yet are there (the SG has such neighbours); a card, tape or finger makes the four read
// alike. So, with expected luminances for all four (a reference read of this chart; the SG's layout alone knows
// only its border), each must lie on the log–log line the detected patches fit between expected luminance and
// working grey as well as the detected patches do (within their 99th percentile, at least a factor 1.25), and the
// four expected levels must span more than twice that tolerance, so that no uniform cover could pass. Fills `why`
// with the figures.
bool block_reads_as_expected(const ChartLayout& L, const std::vector<double>& expected, const WorkingImage& work,
                             const cv::Matx33d& h, const std::optional<LensCalibration>& lens, double pitch_px,
                             const std::vector<bool>& detected, const std::array<int, 4>& block, std::string& why) {
  for (int k : block)
    if (!std::isfinite(expected[static_cast<std::size_t>(k)]) || !(expected[static_cast<std::size_t>(k)] > 0)) return false;
  const double radius = pitch_px * L.patch_size / 6;
  auto got_log = [&](int k) {
    return std::log(working_luminance(work, grid_to_image(h, {L.centre_x(k), L.centre_y(k)}, lens), radius) + 1.0);
  };
  std::vector<double> a, b;
  for (int k = 0; k < L.size(); ++k) {
    const double e = expected[static_cast<std::size_t>(k)];
    if (!detected[static_cast<std::size_t>(k)] || !std::isfinite(e) || !(e > 0)) continue;
    a.push_back(got_log(k));
    b.push_back(std::log(e));
  }
  if (a.size() < 12) return false;
  const double n = static_cast<double>(a.size());
  double ma = 0, mb = 0;
  for (std::size_t k = 0; k < a.size(); ++k) ma += a[k], mb += b[k];
  ma /= n, mb /= n;
  double sab = 0, sbb = 0;
  for (std::size_t k = 0; k < a.size(); ++k) sab += (a[k] - ma) * (b[k] - mb), sbb += (b[k] - mb) * (b[k] - mb);
  if (!(sbb > 0)) return false;
  const double slope = sab / sbb;
  if (!(slope > 0)) return false;
  std::vector<double> res;
  for (std::size_t k = 0; k < a.size(); ++k) res.push_back(std::abs(a[k] - (ma + slope * (b[k] - mb))));
  // As well as the patches that were seen read: all but their worst 1 % (saturated colours stray furthest from
  // the reference's Y in a camera's R + 2G + B).
  std::sort(res.begin(), res.end());
  const double tol = std::max(std::log(1.25), res[res.size() * 99 / 100]);
  double lo = 1e300, hi = -1e300, worst = 0;
  for (int k : block) {
    const double want = ma + slope * (std::log(expected[static_cast<std::size_t>(k)]) - mb);
    lo = std::min(lo, want), hi = std::max(hi, want);
    worst = std::max(worst, std::abs(got_log(k) - want));
  }
  std::ostringstream w;
  w << "worst patch off its expected luminance by a factor " << std::exp(worst) << " (tolerance " << std::exp(tol)
    << "), expected levels spanning a factor " << std::exp(hi - lo);
  why = w.str();
  return worst <= tol && hi - lo > 2 * tol;
}

}  // namespace

ChartLocation locate_chart(const PhotoView& photo, ChartType type, const LocateOptions& o) {
  const ChartLayout& L = chart_layout(type);
  if (!(o.min_confidence >= 0 && o.min_confidence <= 1))
    throw Error(ErrorClass::bad_parameter, "minimum confidence must be within 0..1");
  std::vector<double> expected = L.expected_luminance;
  std::vector<std::vector<int>> groups = L.repeated_neutrals;
  if (o.reference) {
    if (!o.reference->luminance.empty()) {
      if (o.reference->luminance.size() != static_cast<std::size_t>(L.size()))
        throw Error(ErrorClass::bad_parameter, "chart reference has " + std::to_string(o.reference->luminance.size()) +
                                                   " luminances for " + std::to_string(L.size()) + " patches");
      expected = o.reference->luminance;
    }
    if (!o.reference->repeated_neutrals.empty()) groups = o.reference->repeated_neutrals;
    for (const auto& g : groups)
      for (int k : g)
        if (k < 0 || k >= L.size()) throw Error(ErrorClass::bad_parameter, "chart reference names patch index " + std::to_string(k));
  }

  const WorkingImage work = make_working_image(photo);
  const std::vector<Quad> quads = find_patch_quads(work);
  std::vector<cv::Point2d> raw_centres;
  for (const auto& q : quads) raw_centres.push_back(q.centre);
  const std::vector<cv::Point2d> centres = undistort_points(raw_centres, o.lens);

  ChartLocation loc;
  loc.type = type;
  cv::Matx33d H;
  double pitch_px = 0;
  std::vector<bool> detected(static_cast<std::size_t>(L.size()), false);
  std::vector<cv::Point2d> observed(static_cast<std::size_t>(L.size()));  // undistorted centroid of each detected patch
  std::vector<cv::Point2d> seen(static_cast<std::size_t>(L.size()));      // the same centroid as photographed
  Score conf;
  const std::vector<cv::Point2d> grid_corners{{0, 0}, {L.grid_width(), 0}, {L.grid_width(), L.grid_height()}, {0, L.grid_height()}};

  if (o.corners) {
    loc.from_corners = true;
    std::vector<cv::Point2d> given;
    for (const auto& p : *o.corners) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || p.x < 0 || p.y < 0 || p.x > photo.width - 1 || p.y > photo.height - 1)
        throw Error(ErrorClass::bad_parameter, "corner (" + std::to_string(p.x) + ", " + std::to_string(p.y) + ") is outside the photo");
      given.emplace_back(p.x, p.y);
    }
    given = undistort_points(given, o.lens);
    std::vector<cv::Point2f> src, dst;
    for (int k = 0; k < 4; ++k) {
      src.emplace_back(static_cast<float>(grid_corners[static_cast<std::size_t>(k)].x), static_cast<float>(grid_corners[static_cast<std::size_t>(k)].y));
      dst.emplace_back(static_cast<float>(given[static_cast<std::size_t>(k)].x), static_cast<float>(given[static_cast<std::size_t>(k)].y));
    }
    if (std::abs(cv::contourArea(dst)) < 100 || !cv::isContourConvex(dst))
      throw Error(ErrorClass::bad_parameter, "the four corners given do not form a convex quadrilateral",
                  "give the outer corners of the patch grid in order around the chart");
    H = cv::Matx33d(cv::getPerspectiveTransform(src, dst));
    const cv::Point2d mid(L.grid_width() / 2, L.grid_height() / 2);
    pitch_px = (cv::norm(apply(H, mid + cv::Point2d(1, 0)) - apply(H, mid)) + cv::norm(apply(H, mid + cv::Point2d(0, 1)) - apply(H, mid))) / 2;
    // Snap to the patches found near where the corners put them.
    std::vector<cv::Point2d> g, im;
    std::vector<int> which;
    for (int k = 0; k < L.size(); ++k) {
      const cv::Point2d p = apply(H, {L.centre_x(k), L.centre_y(k)});
      int best = -1;
      double bd = 0.3 * pitch_px;
      for (std::size_t q = 0; q < centres.size(); ++q)
        if (cv::norm(centres[q] - p) < bd) bd = cv::norm(centres[q] - p), best = static_cast<int>(q);
      if (best >= 0) {
        g.emplace_back(L.centre_x(k), L.centre_y(k)), im.push_back(centres[static_cast<std::size_t>(best)]), which.push_back(k);
        seen[static_cast<std::size_t>(k)] = raw_centres[static_cast<std::size_t>(best)];
      }
    }
    if (g.size() >= 8) {
      std::vector<unsigned char> inl;
      cv::Mat h2 = cv::findHomography(g, im, cv::RANSAC, 0.15 * pitch_px, inl);
      if (!h2.empty()) {
        double moved = 0;
        for (const auto& c : grid_corners) moved = std::max(moved, cv::norm(apply(cv::Matx33d(h2), c) - apply(H, c)));
        if (moved < 0.5 * pitch_px) {
          H = cv::Matx33d(h2);
          double ss = 0;
          int n = 0;
          for (std::size_t m = 0; m < g.size(); ++m)
            if (inl[m]) {
              detected[static_cast<std::size_t>(which[m])] = true;
              observed[static_cast<std::size_t>(which[m])] = im[m];
              const cv::Point2d r = apply(H, g[m]) - im[m];
              ss += r.dot(r), ++n;
            }
          loc.reprojection_rms_px = n ? std::sqrt(ss / n) : 0;
        } else {
          loc.notes.push_back("the patches found disagree with the corners given by up to " + std::to_string(moved) + " px; kept the corners");
        }
      }
    }
    // The order of the corners fixes the orientation; the luminances must not clearly prefer the other way up.
    const cv::Matx33d turned = H * cv::Matx33d(-1, 0, L.grid_width(), 0, -1, L.grid_height(), 0, 0, 1);
    const double given_score = luminance_agreement(L, expected, work, H, o.lens, pitch_px);
    const double turned_score = luminance_agreement(L, expected, work, turned, o.lens, pitch_px);
    loc.orientation_margin = given_score - turned_score;
    if (loc.orientation_margin < -0.15)
      lower(conf, 0.2, "the patch luminances say the chart is the other way up: the first corner must be at patch " + L.ids.front());
  } else {
    const int min_cells = std::max(6, L.size() / 4);
    auto lat = build_lattice(quads, centres, min_cells);
    if (!lat)
      throw Error(ErrorClass::not_found,
                  "no " + grid_name(L) + " found in the photo: " + std::to_string(quads.size()) +
                      " patch-like squares, no grid of " + std::to_string(min_cells) + " or more",
                  kCornersHint);
    auto choices = placements(L, *lat);
    if (choices.empty()) {
      const bool fits = (lat->ni() <= L.columns && lat->nj() <= L.rows) || (lat->ni() <= L.rows && lat->nj() <= L.columns);
      const std::string found = std::to_string(lat->ni()) + "×" + std::to_string(lat->nj());
      if (fits)
        throw Error(ErrorClass::needs_operator,
                    "found only " + found + " of the " + grid_name(L) + ": the chart is partly covered, outside the frame, or has patches too dark to see",
                    kCornersHint);
      throw Error(ErrorClass::not_found, "found a grid of " + found + " squares, which is not a " + grid_name(L),
                  "check --chart (sg or cc24); " + std::string(kCornersHint));
    }
    score_placements(choices, L, expected, work, *lat, o.lens);
    const auto& best = choices.front();
    loc.orientation_margin = best.margin;
    if (!best.scored) lower(conf, 0, "no expected luminances to tell which way up the chart is");
    else lower(conf, clamp01(best.margin / 0.2), "which way up the chart is stays uncertain (margin " + std::to_string(best.margin) + ")");
    H = lat->to_image * best.grid_to_lattice;
    pitch_px = lat->pitch_px;
    loc.reprojection_rms_px = lat->rms_px;
    for (int k = 0; k < L.size(); ++k) {
      const cv::Point2d cell = apply(best.grid_to_lattice, {L.centre_x(k), L.centre_y(k)});
      const auto it = lat->cells.find({static_cast<int>(std::lround(cell.x)), static_cast<int>(std::lround(cell.y))});
      detected[static_cast<std::size_t>(k)] = it != lat->cells.end();
      if (it != lat->cells.end()) {
        observed[static_cast<std::size_t>(k)] = centres[static_cast<std::size_t>(it->second)];
        seen[static_cast<std::size_t>(k)] = raw_centres[static_cast<std::size_t>(it->second)];
      }
    }
  }

  if (const auto refit = refit_centroids(L, H, detected, observed)) H = refit->first, loc.reprojection_rms_px = refit->second;
  loc.patches_detected = static_cast<int>(std::count(detected.begin(), detected.end(), true));
  const double coverage = double(loc.patches_detected) / L.size();
  lower(conf, clamp01((coverage - 0.3) / 0.3), "only " + std::to_string(loc.patches_detected) + " of " + std::to_string(L.size()) + " patches were seen");
  if (pitch_px > 0) {
    const double rel = loc.reprojection_rms_px / pitch_px;
    lower(conf, clamp01(1 - (rel - 0.04) / 0.08),
          "the patches do not sit on a flat grid (rms " + std::to_string(loc.reprojection_rms_px) +
              " px); is the lens distortion uncorrected?");
  }
  for (const auto& block : undetected_blocks(L, detected)) {
    std::string names;
    for (int k : block) names += (names.empty() ? "" : ", ") + L.ids[static_cast<std::size_t>(k)];
    std::string why;
    if (block_reads_as_expected(L, expected, work, H, o.lens, pitch_px, detected, block, why)) {
      loc.notes.push_back("patches " + names + " show no edges of their own but read as the reference expects (" + why +
                          "): too close to the surround's luminance for an edge, not covered");
      continue;
    }
    lower(conf, 0.1,
          "patches " + names + " show no edges of their own: is the chart partly covered?" +
              (why.empty() ? std::string() : " (" + why + ")"));
    break;
  }

  loc.homography = to_array(H);
  for (int k = 0; k < 4; ++k) {
    const cv::Point2d p = grid_to_image(H, grid_corners[static_cast<std::size_t>(k)], o.lens);
    loc.corners[static_cast<std::size_t>(k)] = {p.x, p.y};
  }
  {
    const cv::Point2d mid(L.grid_width() / 2, L.grid_height() / 2);
    const cv::Point2d d = apply(H, mid + cv::Point2d(1, 0)) - apply(H, mid);
    const int q = static_cast<int>(std::lround(std::atan2(d.y, d.x) * 2 / CV_PI));
    loc.rotation_deg = ((q % 4) + 4) % 4 * 90;
  }
  loc.patches = sample_chart(photo, L, loc.homography, o);
  for (int k = 0; k < L.size(); ++k) {
    auto& p = loc.patches[static_cast<std::size_t>(k)];
    p.detected = detected[static_cast<std::size_t>(k)];
    if (p.detected) p.observed = {seen[static_cast<std::size_t>(k)].x, seen[static_cast<std::size_t>(k)].y};
  }

  if (!groups.empty()) loc.check = check_repeated_neutrals(L, groups, loc.patches, photo.black_level, o.neutral_tolerance);
  else if (!L.neutral_ramp.empty()) loc.check = check_neutral_ramp(L, loc.patches, photo.black_level);
  else loc.check.method = "none";
  if (!loc.check.passed)
    lower(conf, 0.2,
          "the chart's own neutrals disagree (" + loc.check.method + ", worst at " + loc.check.worst_patch + ": " +
              std::to_string(loc.check.worst_disagreement * 100) + " %): the grid is misplaced or the chart is covered");
  loc.confidence = conf.value;
  if (conf.value < 1) loc.notes.push_back("confidence limited by: " + conf.why);
  if (loc.confidence < o.min_confidence) {
    std::ostringstream msg;
    msg << "not sure of the " << L.name << " in this photo (confidence " << loc.confidence << "): " << conf.why;
    throw Error(ErrorClass::needs_operator, msg.str(), kCornersHint);
  }
  return loc;
}

}  // namespace colorlab::analysis
