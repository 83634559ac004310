#include <algorithm>
#include <cmath>
#include <sstream>

#include <opencv2/core.hpp>

#include "internal.hpp"

namespace colorlab::analysis::chart_detail {
namespace {

// Smooth light field over the chart: quadratic in the grid position with ≥ 10 patches, a plane with ≥ 4, else flat.
std::vector<double> basis(double x, double y, int terms) {
  std::vector<double> b{1, x, y, x * x, x * y, y * y};
  b.resize(static_cast<std::size_t>(terms));
  return b;
}

std::vector<double> fit_field(const std::vector<cv::Point2d>& pos, const std::vector<double>& v, int terms,
                              std::vector<double>* coefficients = nullptr) {
  cv::Mat A(static_cast<int>(v.size()), terms, CV_64F), b(static_cast<int>(v.size()), 1, CV_64F), x;
  for (std::size_t k = 0; k < v.size(); ++k) {
    const auto row = basis(pos[k].x, pos[k].y, terms);
    for (int t = 0; t < terms; ++t) A.at<double>(static_cast<int>(k), t) = row[static_cast<std::size_t>(t)];
    b.at<double>(static_cast<int>(k)) = v[k];
  }
  cv::solve(A, b, x, cv::DECOMP_SVD);
  std::vector<double> out(v.size());
  for (std::size_t k = 0; k < v.size(); ++k) {
    const auto row = basis(pos[k].x, pos[k].y, terms);
    double s = 0;
    for (int t = 0; t < terms; ++t) s += row[static_cast<std::size_t>(t)] * x.at<double>(t);
    out[k] = s;
  }
  if (coefficients) coefficients->assign(x.begin<double>(), x.end<double>());
  return out;
}

double mean_of(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / static_cast<double>(v.size());
}

}  // namespace

SelfCheck check_repeated_neutrals(const ChartLayout& L, const std::vector<std::vector<int>>& groups,
                                  const std::vector<ChartPatchSample>& patches, double black, double tolerance) {
  SelfCheck sc;
  sc.method = "repeated neutrals";
  const int channels = patches.empty() ? 1 : patches.front().channels;
  auto pos_of = [&](int k) {
    return cv::Point2d(2 * L.centre_x(k) / L.grid_width() - 1, 2 * L.centre_y(k) / L.grid_height() - 1);
  };
  // The brightest group's level above black sets the scale of every disagreement.
  std::vector<double> top(static_cast<std::size_t>(channels), 1e-9);
  std::size_t brightest = 0;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    double s = 0;
    for (int k : groups[g]) s += patches[static_cast<std::size_t>(k)].value[0].value;
    s /= std::max<std::size_t>(1, groups[g].size());
    for (int c = 0; c < channels; ++c) {
      double m = 0;
      for (int k : groups[g]) m += patches[static_cast<std::size_t>(k)].value[static_cast<std::size_t>(c)].value - black;
      m /= std::max<std::size_t>(1, groups[g].size());
      if (m > top[static_cast<std::size_t>(c)]) {
        top[static_cast<std::size_t>(c)] = m;
        if (c == 0) brightest = g;
      }
    }
  }
  std::ostringstream detail;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const auto& grp = groups[g];
    if (grp.size() < 3) continue;
    std::vector<cv::Point2d> pos;
    for (int k : grp) pos.push_back(pos_of(k));
    const int terms = grp.size() >= 10 ? 6 : grp.size() >= 4 ? 3
                                                             : 1;
    double group_worst = 0;
    for (int c = 0; c < channels; ++c) {
      std::vector<double> v;
      for (int k : grp) v.push_back(patches[static_cast<std::size_t>(k)].value[static_cast<std::size_t>(c)].value);
      const auto fitted = fit_field(pos, v, terms);
      for (std::size_t m = 0; m < v.size(); ++m) {
        const double d = std::abs(v[m] - fitted[m]) / top[static_cast<std::size_t>(c)];
        group_worst = std::max(group_worst, d);
        if (d > sc.worst_disagreement) {
          sc.worst_disagreement = d;
          sc.worst_patch = L.ids[static_cast<std::size_t>(grp[m])];
        }
      }
      if (g == brightest && c == std::min(1, channels - 1)) {
        std::vector<double> coef;
        fit_field(pos, v, 3, &coef);
        const double level = mean_of(v) - black;
        if (level > 0) sc.gradient_x = 2 * coef[1] / level, sc.gradient_y = 2 * coef[2] / level;
      }
    }
    detail << (g ? "; " : "") << grp.size() << " patches like " << L.ids[static_cast<std::size_t>(grp.front())]
           << ": worst " << group_worst * 100 << " %";
  }
  sc.passed = sc.worst_disagreement <= tolerance;
  sc.detail = detail.str();
  return sc;
}

SelfCheck check_neutral_ramp(const ChartLayout& L, const std::vector<ChartPatchSample>& patches, double black) {
  SelfCheck sc;
  sc.method = "neutral ramp";
  const auto& ramp = L.neutral_ramp;
  const int channels = patches.empty() ? 1 : patches.front().channels;
  for (int c = 0; c < channels; ++c) {
    std::vector<double> v;
    for (int k : ramp) v.push_back(patches[static_cast<std::size_t>(k)].value[static_cast<std::size_t>(c)].value);
    const double scale = std::max(1e-9, v.front() - black);
    // Each step must not brighten by more than 2 % of white, and white must stand well above black.
    for (std::size_t m = 1; m < v.size(); ++m) {
      const double rise = (v[m] - v[m - 1]) / scale;
      if (rise > sc.worst_disagreement) {
        sc.worst_disagreement = rise;
        sc.worst_patch = L.ids[static_cast<std::size_t>(ramp[m])];
      }
    }
    if ((v.front() - v.back()) / scale < 0.3) {
      sc.worst_disagreement = std::max(sc.worst_disagreement, 1.0);
      sc.worst_patch = L.ids[static_cast<std::size_t>(ramp.front())];
    }
  }
  sc.passed = sc.worst_disagreement <= 0.02;
  sc.detail = "neutral row " + L.ids[static_cast<std::size_t>(ramp.front())] + "…" + L.ids[static_cast<std::size_t>(ramp.back())] +
              (sc.passed ? " falls from white to black" : " does not fall from white to black at " + sc.worst_patch);
  return sc;
}

}  // namespace colorlab::analysis::chart_detail
