// Light: the rendering's floor luminance at the LS-110's spots, and over the floor-luminance map's grid.
#include <cmath>
#include <limits>
#include <string>

#include "colorlab/core/error.hpp"
#include "comparisons.hpp"
#include "rendering_noise.hpp"
#include "rendering_sample.hpp"

namespace colorlab::verify::detail {
namespace {

std::string spot_name(int row, int col) { return "r" + std::to_string(row) + "c" + std::to_string(col); }

struct Site {
  int row, col;
  double measured;
  double own_sd;  // the instrument's own standard uncertainty, cd/m²
  const char* own_name;
  PixelRect region;
};

void compare_sites(const Rendering& r, const std::vector<Site>& sites, const char* kind, double accuracy_px,
                   const MeasuredScene& s, const CompareOptions& o, Verification& v) {
  const ToXyz tx(r);
  std::vector<double> rendered;
  std::vector<double> ratios;
  for (const auto& site : sites) {
    rendered.push_back(tx(region_mean(r, site.region)).Y);
    ratios.push_back(site.measured / rendered.back());
  }
  ScaleUsed sc{kind, "given", o.scale.value_or(1.0)};
  if (!o.scale) {
    sc.how = "fitted";
    sc.factor = median_ratio(ratios, kind);
  }
  v.scales.push_back(sc);
  const double drift_sd = s.lamp_drift_bound / std::sqrt(3.0);
  RenderingNoise noise;
  if (o.rendering_noise) {
    std::vector<PixelRect> regions;
    for (const auto& site : sites) regions.push_back(site.region);
    noise = rendering_noise(r, regions, tx.matrix().row(1), o.noise_neighbours);
  }
  for (std::size_t i = 0; i < sites.size(); ++i) {
    const auto& site = sites[i];
    if (!(site.measured > 0))
      throw Error(ErrorClass::bad_data, std::string(kind) + " " + spot_name(site.row, site.col) + " has no positive luminance");
    const double lr = rendered[i] * sc.factor;
    Budget b;
    b.add_vector(site.own_name, Eigen::VectorXd::Constant(1, site.own_sd));
    if (!noise.covariance.empty()) b.add("rendering noise", sc.factor * sc.factor * noise.covariance[i]);
    if (sc.how == "given" && drift_sd > 0) b.add_vector("lamp drift", Eigen::VectorXd::Constant(1, site.measured * drift_sd));
    if (accuracy_px > 0)
      for (auto [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
        const double d = tx(shifted_mean(r, site.region, dx, dy)).Y - tx(shifted_mean(r, site.region, -dx, -dy)).Y;
        b.add_vector("misregistration", Eigen::VectorXd::Constant(1, 0.5 * accuracy_px * d * sc.factor));
      }
    Comparison c;
    c.kind = kind;
    c.where = spot_name(site.row, site.col);
    c.rendered = {lr};
    c.measured = {site.measured};
    c.noise_left_out = noise.own_level(i);
    conclude(c, Eigen::VectorXd::Constant(1, lr - site.measured), b, o, lr / site.measured - 1, 1 / site.measured,
             o.cannot_tell_relative);
    v.comparisons.push_back(std::move(c));
  }
}

}  // namespace

void compare_light(const Rendering& r, const MeasuredScene& s, const CompareOptions& o, Verification& v) {
  if (!s.spots.empty()) {
    std::vector<Site> sites;
    for (const auto& p : s.spots) {
      if (p.readings < 1 || p.reading_sd < 0)
        throw Error(ErrorClass::bad_data, "spot " + spot_name(p.row, p.col) + " has no readings or a negative repeatability");
      sites.push_back({p.row, p.col, p.luminance_cd_m2, p.reading_sd / std::sqrt(static_cast<double>(p.readings)),
                       "ls110 repeatability", p.rendering_region});
    }
    compare_sites(r, sites, "light_spot", s.floor_accuracy_px, s, o, v);
  }
  if (!s.floor.empty()) {
    std::vector<Site> sites;
    for (const auto& f : s.floor)
      sites.push_back({f.row, f.col, f.luminance_cd_m2, f.relative_sd * f.luminance_cd_m2, "floor map", f.rendering_region});
    const auto first = v.comparisons.size();
    compare_sites(r, sites, "light_floor", s.floor_accuracy_px, s, o, v);
    // The difference image over the floor's grid.
    int rows = s.floor_rows, cols = s.floor_cols;
    for (const auto& f : s.floor) {
      rows = std::max(rows, f.row + 1);
      cols = std::max(cols, f.col + 1);
    }
    v.floor_ratio.assign(static_cast<std::size_t>(rows),
                         std::vector<double>(static_cast<std::size_t>(cols), std::numeric_limits<double>::quiet_NaN()));
    for (std::size_t i = 0; i < s.floor.size(); ++i)
      v.floor_ratio[static_cast<std::size_t>(s.floor[i].row)][static_cast<std::size_t>(s.floor[i].col)] =
          v.comparisons[first + i].difference;
  }
}

}  // namespace colorlab::verify::detail
