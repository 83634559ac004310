#include "synthetic_lab.hpp"

#include <algorithm>
#include <cmath>

#include "colorlab/analysis/color_difference.hpp"
#include "colorlab/analysis/standard_data.hpp"

namespace colorlab::verify::testing {
namespace {

constexpr double kStep = 10.0;        // nm
constexpr double kWhiteCdM2 = 200.0;  // the lamp's perfect diffuser at the chart
constexpr double kFloorReflectance = 0.8;
constexpr double kDriftBound = 0.01;  // the stability campaigns accept (docs/campaigns.md: ≤ 1 % rise)
constexpr double kLocatorPx = 0.5;    // one σ
constexpr double kFloorPx = 0.5;
constexpr double kLs110Relative = 0.003;  // one reading
constexpr int kLs110Readings = 2;
constexpr double kFloorMapRelative = 0.01;  // flat-field residual (docs/campaigns.md floor-luminance)
constexpr double kWhiteCounts = 3000;       // 12-bit raw, the white below clipping

Eigen::RowVectorXd resampled(const analysis::SpectralSet& s, int row, const std::vector<double>& to) {
  const Eigen::MatrixXd r = analysis::resampling_matrix(s.wavelengths, to, analysis::Interpolation::linear);
  return (r * s.values.row(row).transpose()).transpose();
}

double gauss(double x, double mu, double sigma) { return std::exp(-0.5 * (x - mu) * (x - mu) / (sigma * sigma)); }

analysis::Lab lab_of(const Eigen::Vector3d& xyz, const analysis::Xyz& white) {
  return analysis::xyz_to_lab({xyz[0], xyz[1], xyz[2]}, white);
}

}  // namespace

Rendering with_render_noise(const Rendering& r, std::mt19937_64& rng, double sd, bool correlated, bool per_band) {
  std::normal_distribution<double> N(0, 1);
  if (per_band) {
    Rendering out = r;
    const auto chart_values = static_cast<std::size_t>(10 + 10 * 10) * static_cast<std::size_t>(r.width * r.channels());
    for (std::size_t i = 0; i < chart_values && i < out.pixels.size(); ++i) out.pixels[i] = static_cast<float>(out.pixels[i] * (1 + sd * N(rng)));
    return out;
  }
  const auto w = static_cast<std::size_t>(r.width) + 1, h = static_cast<std::size_t>(r.height) + 1;
  std::vector<double> white(w * h);
  for (auto& x : white) x = N(rng);
  Rendering out = r;
  const auto n = static_cast<std::size_t>(r.channels());
  for (std::size_t y = 0; y + 1 < h; ++y)
    for (std::size_t x = 0; x + 1 < w; ++x) {
      const double e = correlated ? 0.5 * (white[y * w + x] + white[y * w + x + 1] + white[(y + 1) * w + x] + white[(y + 1) * w + x + 1])
                                  : white[y * w + x];
      float* p = out.pixels.data() + (y * (w - 1) + x) * n;
      for (std::size_t c = 0; c < n; ++c) p[c] = static_cast<float>(p[c] * (1 + sd * e));
    }
  return out;
}

SyntheticLab::SyntheticLab() {
  for (double w = 400; w <= 700.5; w += kStep) wl_.push_back(w);
  const auto n = static_cast<Eigen::Index>(wl_.size());

  const auto obs = analysis::load_observer(analysis::Observer::cie1931_2deg);
  cmf_.resize(3, n);
  for (int k = 0; k < 3; ++k) cmf_.row(k) = 683.0 * kStep * resampled(obs, k, wl_);
  lamp_ = lamp_named("F2");  // the cabinet's CWF is CIE F2 (docs/campaigns.md)
  const Eigen::Vector3d w = cmf_ * lamp_.transpose();
  white_ = {w[0], w[1], w[2]};

  // Smooth reflectances: 14 neutrals from black to white, then bumps on a base, as a chart's colours are.
  std::mt19937_64 rng(20061103);
  std::uniform_real_distribution<double> u(0, 1);
  refl_.resize(kPatches, n);
  for (int i = 0; i < kPatches; ++i) {
    if (i < 14) {
      refl_.row(i).setConstant(0.03 + 0.87 * i / 13.0);
      continue;
    }
    const double base = 0.04 + 0.25 * u(rng);
    const int bumps = 1 + static_cast<int>(u(rng) * 3);
    std::vector<std::array<double, 3>> b;
    for (int k = 0; k < bumps; ++k) b.push_back({0.1 + 0.6 * u(rng), 400 + 300 * u(rng), 25 + 60 * u(rng)});
    for (Eigen::Index j = 0; j < n; ++j) {
      double v = base;
      for (const auto& [a, mu, s] : b) v += a * gauss(wl_[static_cast<std::size_t>(j)], mu, s);
      refl_(i, j) = std::clamp(v, 0.02, 0.95);
    }
  }

  // The camera: close to a linear combination of the observer (so a 3 × 3 characterization is good to about a
  // ΔE00) with bumps of its own, scaled so the white reads kWhiteCounts in green.
  camera_.resize(3, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double l = wl_[static_cast<std::size_t>(j)];
    camera_(0, j) = cmf_(0, j) * (1 + 0.1 * gauss(l, 620, 15));
    camera_(1, j) = cmf_(1, j) * (1 + 0.1 * gauss(l, 500, 20));
    camera_(2, j) = cmf_(2, j) * (1 + 0.1 * gauss(l, 470, 15)) + 0.05 * cmf_(1, j);
  }
  camera_ *= kWhiteCounts / (camera_.row(1).dot(lamp_));

  // Layout: the chart's 14 × 10 patches (8 px, pitch 10, sampled over the inner 5 × 5) and the floor's 8 × 10
  // spots (3 × 3 px, pitch 14 × 10) below it.
  for (int r = 0; r < 10; ++r)
    for (int c = 0; c < 14; ++c) patch_regions_.push_back({10 + 10 * c + 2, 10 + 10 * r + 2, 5, 5});
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kCols; ++c) spot_regions_.push_back({10 + 14 * c + 6, 120 + 10 * r + 4, 3, 3});
  width_ = 160;
  height_ = 210;
}

Eigen::RowVectorXd SyntheticLab::lamp_named(const std::string& name) const {
  Eigen::RowVectorXd l = resampled(analysis::load_illuminant(name), 0, wl_);
  const double y = cmf_.row(1).dot(l);
  return l * (kWhiteCdM2 / y);
}

double SyntheticLab::floor_field(double x, double y) const {
  const double u = (x - 80) / 70, v = (y - 160) / 40;
  return 1 - 0.35 * u * u - 0.2 * v * v + 0.1 * u;
}

double SyntheticLab::floor_mean(const PixelRect& g, double dx, double dy) const {
  double s = 0;
  for (int y = g.y; y < g.y + g.h; ++y)
    for (int x = g.x; x < g.x + g.w; ++x) s += floor_field(x + 0.5 + dx, y + 0.5 + dy);
  return s / (g.w * g.h);
}

Rendering SyntheticLab::render(const Defects& d, const Eigen::MatrixXd* reflectances) const {
  Rendering r;
  r.width = width_;
  r.height = height_;
  r.encoding = Encoding::spectral;
  r.wavelengths_nm = wl_;
  r.units = "W.m^-2.sr^-1.nm^-1";
  r.source_format = "synthetic";
  const auto n = static_cast<std::size_t>(wl_.size());
  r.pixels.assign(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * n, 0.0f);
  Eigen::RowVectorXd lamp = d.lamp_spd.empty() ? lamp_ : lamp_named(d.lamp_spd);
  lamp *= d.lamp_factor;
  auto put = [&](int x, int y, const Eigen::RowVectorXd& radiance) {
    float* p = r.pixels.data() + (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * n;
    for (std::size_t j = 0; j < n; ++j) p[j] = static_cast<float>(radiance[static_cast<Eigen::Index>(j)]);
  };
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      if (y >= 120 && y < 200 && x >= 10 && x < 150) {
        const int row = (y - 120) / 10, col = (x - 10) / 14;
        double rho = kFloorReflectance * floor_field(x + 0.5, y + 0.5);
        if (floor_region(row, col, d)) rho *= d.floor_factor;
        put(x, y, lamp * rho);
      } else {
        put(x, y, lamp * 0.5);
      }
    }
  for (int i = 0; i < kPatches; ++i) {
    const int row = i / 14, col = i % 14;
    Eigen::RowVectorXd rho = reflectances ? reflectances->row(i) : refl_.row(i);
    if (i == d.patch) rho *= d.patch_factor;
    const Eigen::RowVectorXd rad = rho.cwiseProduct(lamp);
    for (int y = 10 + 10 * row; y < 18 + 10 * row; ++y)
      for (int x = 10 + 10 * col; x < 18 + 10 * col; ++x) put(x, y, rad);
  }
  return r;
}

double SyntheticLab::factor_for_de00(int patch, double de00) const {
  const Eigen::RowVectorXd rad = refl_.row(patch).cwiseProduct(lamp_);
  const auto ref = lab_of(cmf_ * rad.transpose(), white_);
  double lo = 1, hi = 2;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (analysis::delta_e2000(ref, lab_of(cmf_ * (rad * mid).transpose(), white_)) < de00 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

std::vector<double> SyntheticLab::true_de00(const Defects& d) const {
  Eigen::RowVectorXd lamp = d.lamp_spd.empty() ? lamp_ : lamp_named(d.lamp_spd);
  lamp *= d.lamp_factor;
  std::vector<double> out;
  for (int i = 0; i < kPatches; ++i) {
    const Eigen::RowVectorXd a = refl_.row(i).cwiseProduct(lamp_);
    Eigen::RowVectorXd b = refl_.row(i).cwiseProduct(lamp);
    if (i == d.patch) b *= d.patch_factor;
    out.push_back(analysis::delta_e2000(lab_of(cmf_ * a.transpose(), white_), lab_of(cmf_ * b.transpose(), white_)));
  }
  return out;
}

MeasuredScene SyntheticLab::measure(std::mt19937_64& rng, const Sources& s, Eigen::MatrixXd* read) const {
  std::normal_distribution<double> N(0, 1);
  std::uniform_real_distribution<double> U(-1, 1);
  // The chart-read first, and only when it has noise: the other draws stay what they were without it.
  Eigen::MatrixXd spectra = refl_;
  if (s.read_gain_sd > 0 || s.read_band_sd > 0)
    for (Eigen::Index i = 0; i < spectra.rows(); ++i) {
      const double gain = 1 + s.read_gain_sd * N(rng);
      for (Eigen::Index j = 0; j < spectra.cols(); ++j) spectra(i, j) *= gain * (1 + s.read_band_sd * N(rng));
    }
  if (read) *read = spectra;
  const Eigen::MatrixXd& reference = s.read_is_reference ? spectra : refl_;
  MeasuredScene m;
  m.lamp = "CWF";
  m.runs = {"synthetic"};
  m.lamp_drift_bound = s.drift ? kDriftBound : 0;
  m.locator_accuracy_px = s.misregistration ? kLocatorPx : 0;
  m.floor_accuracy_px = s.misregistration ? kFloorPx : 0;
  auto drift = [&] { return s.drift ? kDriftBound * U(rng) : 0.0; };
  auto counts_sd = [&](double v) { return s.frame_noise ? std::sqrt(1.0 + std::pow(0.002 * v, 2)) : 0.0; };

  // The chart as the camera saw it, and the same chart in the characterization's own training photograph.
  Eigen::MatrixXd truth_counts(kPatches, 3), train(kPatches, 3), truth_xyz(kPatches, 3);
  for (int i = 0; i < kPatches; ++i) {
    const Eigen::RowVectorXd rad = refl_.row(i).cwiseProduct(lamp_);
    truth_counts.row(i) = (camera_ * rad.transpose()).transpose();
    truth_xyz.row(i) = (cmf_ * reference.row(i).cwiseProduct(lamp_).transpose()).transpose() * (100.0 / white_.Y);
    for (int c = 0; c < 3; ++c) train(i, c) = truth_counts(i, c) + counts_sd(truth_counts(i, c)) * N(rng);
  }
  const double eps = drift();
  for (int i = 0; i < kPatches; ++i) {
    PatchMeasurement p;
    p.id = std::string(1, static_cast<char>('A' + i % 14)) + std::to_string(1 + i / 14);
    for (int c = 0; c < 3; ++c) {
      const double v = truth_counts(i, c) * (1 + eps);
      p.frame_noise[static_cast<std::size_t>(c)] = counts_sd(v);
      p.camera[static_cast<std::size_t>(c)] = v + p.frame_noise[static_cast<std::size_t>(c)] * N(rng);
    }
    p.rendering_region = patch_regions_[static_cast<std::size_t>(i)];
    m.patches.push_back(p);
  }

  // §7.3: camera -> XYZ by least squares (3 × 3), its held-out errors by the hat matrix.
  Characterization ch;
  ch.name = "linear 3x3 (synthetic)";
  ch.white = {white_.X * 100 / white_.Y, 100, white_.Z * 100 / white_.Y};
  const Eigen::Matrix3d gram_inv = (train.transpose() * train).inverse();
  const Eigen::Matrix3d M = gram_inv * train.transpose() * truth_xyz;
  for (int i = 0; i < kPatches; ++i) {
    const double h = train.row(i) * gram_inv * train.row(i).transpose();
    const Eigen::RowVector3d e = truth_xyz.row(i) - train.row(i) * M;
    const Eigen::RowVector3d loo = truth_xyz.row(i) - e / (1 - h);
    const auto ref = lab_of(truth_xyz.row(i).transpose(), ch.white);
    ch.cv_lab.push_back(ref);
    const auto held_out = lab_of(loo.transpose(), ch.white);
    ch.cv_error.push_back({held_out.L - ref.L, held_out.a - ref.a, held_out.b - ref.b});
  }
  ch.to_xyz = [M](const Rgb3& c) {
    const Eigen::RowVector3d x = Eigen::RowVector3d(c[0], c[1], c[2]) * M;
    return analysis::Xyz{x[0], x[1], x[2]};
  };
  m.characterization = ch;

  // §7.4: the sensitivities on 16 smooth bumps, fitted to the training counts (ridge), held-out by the hat matrix.
  BlackBox bb;
  bb.wavelengths_nm = wl_;
  const auto n = static_cast<Eigen::Index>(wl_.size());
  if (s.characterization) {
    constexpr int kBasis = 16;
    Eigen::MatrixXd basis(n, kBasis);
    for (Eigen::Index j = 0; j < n; ++j)
      for (int k = 0; k < kBasis; ++k) basis(j, k) = gauss(wl_[static_cast<std::size_t>(j)], 400 + 20 * k, 15);
    Eigen::MatrixXd A(kPatches, kBasis);
    for (int i = 0; i < kPatches; ++i) A.row(i) = reference.row(i).cwiseProduct(lamp_) * kStep * basis;
    const Eigen::MatrixXd G = (A.transpose() * A + 1e-6 * (A.transpose() * A).trace() / kBasis *
                                                       Eigen::MatrixXd::Identity(kBasis, kBasis))
                                  .inverse();
    const Eigen::MatrixXd coef = G * A.transpose() * train;
    const Eigen::MatrixXd fitted = A * coef;
    for (int c = 0; c < 3; ++c) {
      const Eigen::VectorXd sens = basis * coef.col(c);
      bb.sensitivity[static_cast<std::size_t>(c)].assign(sens.data(), sens.data() + sens.size());
    }
    for (int i = 0; i < kPatches; ++i) {
      const double h = A.row(i) * G * A.row(i).transpose();
      Rgb3 res{}, cam{};
      for (int c = 0; c < 3; ++c) {
        res[static_cast<std::size_t>(c)] = (fitted(i, c) - train(i, c)) / (1 - h);
        cam[static_cast<std::size_t>(c)] = train(i, c);
      }
      bb.cv_camera.push_back(cam);
      bb.cv_residual.push_back(res);
    }
  } else {
    for (int c = 0; c < 3; ++c)
      for (Eigen::Index j = 0; j < n; ++j) bb.sensitivity[static_cast<std::size_t>(c)].push_back(camera_(c, j) / kStep);
    for (int i = 0; i < kPatches; ++i) {
      bb.cv_camera.push_back({truth_counts(i, 0), truth_counts(i, 1), truth_counts(i, 2)});
      bb.cv_residual.push_back({1e-3, 1e-3, 1e-3});
    }
  }
  m.black_box = bb;

  // The white at the chart, metered; the cabinet-grid's spots; the floor-luminance map.
  const double ls_sd = s.ls110 ? kLs110Relative : 1e-9;
  m.white_relative_sd = ls_sd / std::sqrt(static_cast<double>(kLs110Readings));
  m.white_luminance_cd_m2 = white_.Y * (1 + m.white_relative_sd * N(rng));
  const double floor_eps = drift();
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kCols; ++c) {
      const auto& g = spot_regions_[static_cast<std::size_t>(r * kCols + c)];
      const double a = m.floor_accuracy_px;
      const double truth = kFloorReflectance * white_.Y * floor_mean(g, a * N(rng), a * N(rng));
      SpotMeasurement sp;
      sp.row = r;
      sp.col = c;
      sp.readings = kLs110Readings;
      sp.reading_sd = ls_sd * truth;
      sp.luminance_cd_m2 = truth * (1 + drift()) + sp.reading_sd / std::sqrt(double(kLs110Readings)) * N(rng);
      sp.rendering_region = g;
      m.spots.push_back(sp);

      FloorCell f;
      f.row = r;
      f.col = c;
      f.relative_sd = s.floor_map ? kFloorMapRelative : 1e-9;
      const double seen = kFloorReflectance * white_.Y * floor_mean(g, a * N(rng), a * N(rng));
      f.luminance_cd_m2 = seen * (1 + floor_eps) * (1 + f.relative_sd * N(rng));
      f.rendering_region = g;
      m.floor.push_back(f);
    }
  m.floor_rows = kRows;
  m.floor_cols = kCols;
  return m;
}

}  // namespace colorlab::verify::testing
