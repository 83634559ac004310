// docs/ACCURACY.md, black box: the distribution over noise draws of the curve error and of the credible band's coverage
// for one camera (prior from the other camspec cameras), and the band itself on the worst draw.
//
//   bench_analysis_blackbox [--camera Canon_20D] [--draws 200] [--noise 0.005] [--narrowband K] [--pick even|sd]
//
// --narrowband K (issue 26: what the lab would have to measure): K narrow-band readings added to the chart, each the
// camera's RAW for a 10 nm-wide source at one band of the grid (a monochromator step or a narrow-band LED), bright
// enough for 45 % of full scale in the channel that sees it most, with the same multiplicative noise. Which bands:
// `even` spreads K over 400–720 nm; `sd` (greedy, on seed 1000, not one of the scored draws) adds, one at a time,
// the band where the current posterior's standard deviation relative to each estimated curve's peak is largest
// (the lab knows the estimate, not the truth). Printed
// first: the singular values of the chart's radiance matrix and of each channel's prior, the dimensions they span.
//
// Synthesis as in tests/analysis: SG (X-Rite pre-2014) × D65 at 10 nm over 400–720 nm, brightest patch at 90 % of
// 4095, multiplicative Gaussian RAW noise, seeds 0…draws−1.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <random>
#include <string>

#include "colorlab/analysis/blackbox.hpp"
#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/analysis/statistics.hpp"
#include "colorlab/core/data_paths.hpp"

namespace ca = colorlab::analysis;

int main(int argc, char** argv) {
  std::string camera = "Canon_20D";
  int draws = 200;
  double noise = 0.005;
  int narrowband = 0;
  std::string pick = "sd";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--camera") camera = v;
    else if (a == "--draws") draws = std::stoi(v);
    else if (a == "--noise") noise = std::stod(v);
    else if (a == "--narrowband") narrowband = std::stoi(v);
    else if (a == "--pick") pick = v;
    else {
      std::cerr << "unknown option " << a << "\n";
      return 2;
    }
  }
  const auto cams_file = colorlab::paths::shared_data_file("camera_ssf_camspec_jiang2013_28cams_10nm_400_720.csv");
  const auto sg_file = colorlab::paths::shared_data_file("colorcheckersg_xrite_before_nov2014_dcamprof_10nm_380_730.csv");
  if (!cams_file || !sg_file) {
    std::cerr << "needs ../shared/data (camspec curves, SG spectra)\n";
    return 1;
  }
  const auto cams = ca::read_spectra(*cams_file);
  const auto refl = ca::resample(ca::read_spectra(*sg_file), cams.wavelengths, ca::Interpolation::linear);
  const auto lamp = ca::resample(ca::load_illuminant("D65"), cams.wavelengths, ca::Interpolation::linear);
  Eigen::MatrixXd spectra = refl.values.array().rowwise() * lamp.values.row(0).array();
  ca::BlackBoxOptions o;
  o.prior = ca::learn_sensitivity_prior(cams, cams.wavelengths, {camera});
  Eigen::MatrixXd truth(3, static_cast<Eigen::Index>(cams.wavelengths.size()));
  for (int c = 0; c < 3; ++c) truth.row(c) = cams.values.row(static_cast<Eigen::Index>(cams.require(camera + "_" + "RGB"[c])));
  const double gain = 4095 * 0.9 / (spectra * truth.transpose()).maxCoeff();
  truth *= gain;
  const auto bands = static_cast<Eigen::Index>(cams.wavelengths.size());

  // What the chart can see: singular values of its radiance matrix (patches × bands), relative to the largest.
  {
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(spectra);
    const Eigen::VectorXd sv = svd.singularValues() / svd.singularValues()(0);
    auto above = [&](double t) { return (sv.array() > t).count(); };
    double total = sv.array().square().sum(), acc = 0;
    int k99 = 0, k999 = 0;
    for (Eigen::Index k = 0; k < sv.size(); ++k) {
      acc += sv(k) * sv(k);
      if (k99 == 0 && acc >= 0.99 * total) k99 = static_cast<int>(k + 1);
      if (k999 == 0 && acc >= 0.999 * total) k999 = static_cast<int>(k + 1);
    }
    std::printf("chart radiance matrix (%ld patches x %ld bands): singular values / the largest:", static_cast<long>(spectra.rows()),
                static_cast<long>(bands));
    for (Eigen::Index k = 0; k < sv.size(); ++k) std::printf(" %.2g", sv(k));
    std::printf("\n  above 1e-2: %ld, above 5e-3 (the RAW noise): %ld, above 1e-3: %ld of %ld; 99 %% of the energy in %d, 99.9 %% in %d\n",
                static_cast<long>(above(1e-2)), static_cast<long>(above(noise)), static_cast<long>(above(1e-3)), static_cast<long>(sv.size()),
                k99, k999);
    for (std::size_t c = 0; c < 3; ++c) {
      const auto& pc = o.prior->channels[c];
      std::printf("  prior %c: %ld principal directions from %zu cameras, sdev / the largest:", "RGB"[c], static_cast<long>(pc.sdev.size()),
                  o.prior->cameras.size());
      for (Eigen::Index k = 0; k < pc.sdev.size(); ++k) std::printf(" %.2g", pc.sdev(k) / pc.sdev(0));
      // How much of the true curve (minus the prior's mean, at the truth's scale) the prior's span cannot express.
      const Eigen::VectorXd t = truth.row(static_cast<Eigen::Index>(c)).transpose() / truth.row(static_cast<Eigen::Index>(c)).maxCoeff();
      const double a = t.dot(pc.mean) / pc.mean.squaredNorm();
      const Eigen::VectorXd r = t - a * pc.mean;
      // The prior's span in practice: its leading directions (the rest carry ≤ 10 % of the first one's spread).
      std::printf("; the truth (peak 1, minus its fit to the mean) outside the first k directions, worst band, %% of peak:");
      for (const Eigen::Index k : {Eigen::Index{4}, Eigen::Index{8}, Eigen::Index{12}, pc.sdev.size()}) {
        const Eigen::MatrixXd d = pc.directions.leftCols(std::min(k, pc.directions.cols()));
        const Eigen::VectorXd outside = r - d * (d.transpose() * r);
        std::printf(" k=%ld %.1f", static_cast<long>(k), 100 * outside.cwiseAbs().maxCoeff());
      }
      std::printf("\n");
    }
  }

  // Narrow-band readings: one row of the radiance matrix each, non-zero at one band.
  std::vector<Eigen::Index> picked;
  auto add_reading = [&](Eigen::Index k) {
    const double response = truth.col(k).maxCoeff();
    Eigen::MatrixXd grown(spectra.rows() + 1, bands);
    grown.topRows(spectra.rows()) = spectra;
    grown.row(spectra.rows()).setZero();
    grown(spectra.rows(), k) = 4095 * 0.45 / response;
    spectra = grown;
    picked.push_back(k);
  };
  auto noisy = [&](unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> nd(0, 1);
    Eigen::MatrixXd raw = spectra * truth.transpose();
    for (Eigen::Index i = 0; i < raw.rows(); ++i)
      for (int c = 0; c < 3; ++c) raw(i, c) *= 1 + noise * nd(rng);
    return raw;
  };
  for (int j = 0; j < narrowband; ++j) {
    Eigen::Index k = 0;
    if (pick == "even") {
      k = narrowband == 1 ? bands / 2 : static_cast<Eigen::Index>(std::lround(static_cast<double>(j) * static_cast<double>(bands - 1) / (narrowband - 1)));
    } else {
      const auto m = ca::fit_blackbox(spectra, noisy(1000), o);
      double worst = -1;
      for (Eigen::Index b = 0; b < bands; ++b)
        for (Eigen::Index c = 0; c < 3; ++c)
          if (const double r = m.sensitivity_sdev(c, b) / m.sensitivities.row(c).maxCoeff(); r > worst) {
            worst = r;
            k = b;
          }
    }
    add_reading(k);
  }
  if (narrowband > 0) {
    std::printf("\n%d narrow-band readings (%s) at nm:", narrowband, pick.c_str());
    for (const auto k : picked) std::printf(" %.0f", cams.wavelengths[static_cast<std::size_t>(k)]);
    std::printf("\n");
  }
  const Eigen::MatrixXd clean = spectra * truth.transpose();

  std::array<std::vector<double>, 3> err, coverage;
  std::array<int, 3> worst_seed{};
  std::array<int, 3> misses{}, misses_inside{};  // band values off by > 10 % of peak, and how many the band holds
  for (int seed = 0; seed < draws; ++seed) {
    std::mt19937 rng(static_cast<unsigned>(seed));
    std::normal_distribution<double> nd(0, 1);
    Eigen::MatrixXd raw = clean;
    for (Eigen::Index i = 0; i < raw.rows(); ++i)
      for (int c = 0; c < 3; ++c) raw(i, c) *= 1 + noise * nd(rng);
    const auto m = ca::fit_blackbox(spectra, raw, o);
    for (std::size_t c = 0; c < 3; ++c) {
      const auto ci = static_cast<Eigen::Index>(c);
      const auto band = ca::credible_band(m.sensitivities.row(ci).transpose(), m.sensitivity_sdev.row(ci).transpose());
      int in = 0;
      for (Eigen::Index k = 0; k < band.lower.size(); ++k) {
        const bool inside = truth(ci, k) >= band.lower(k) && truth(ci, k) <= band.upper(k);
        in += inside;
        if (std::abs(m.sensitivities(ci, k) - truth(ci, k)) > 0.10 * truth.row(ci).maxCoeff()) {
          ++misses[c];
          misses_inside[c] += inside;
        }
      }
      const double e = (m.sensitivities.row(ci) - truth.row(ci)).cwiseAbs().maxCoeff() / truth.row(ci).maxCoeff();
      if (err[c].empty() || e > *std::max_element(err[c].begin(), err[c].end())) worst_seed[c] = seed;
      err[c].push_back(e);
      coverage[c].push_back(static_cast<double>(in) / static_cast<double>(band.lower.size()));
    }
  }
  std::printf("\n%s, %d draws, %.1f %% noise, prior from %zu other camspec cameras, %ld chart rows + %d narrow-band readings\n\n",
              camera.c_str(), draws, 100 * noise, o.prior->cameras.size(), static_cast<long>(spectra.rows()) - narrowband, narrowband);
  std::printf("| channel | curve error median / p95 / max (%% of peak) | draws within 10 %% | band coverage median / min | draws with coverage >= 90 %% | values off > 10 %%: inside band |\n|---|---|---|---|---|---|\n");
  for (std::size_t c = 0; c < 3; ++c) {
    auto e = err[c];
    std::sort(e.begin(), e.end());
    const auto s = ca::summarize(err[c]), cv = ca::summarize(coverage[c]);
    const double p95 = e[static_cast<std::size_t>(0.95 * static_cast<double>(e.size() - 1))];
    const auto ok = std::count_if(e.begin(), e.end(), [](double x) { return x <= 0.10; });
    const auto covered = std::count_if(coverage[c].begin(), coverage[c].end(), [](double x) { return x >= 0.90; });
    std::printf("| %c | %.1f / %.1f / %.1f | %.1f %% | %.0f %% / %.0f %% | %.1f %% | %d / %d |\n", "RGB"[c], 100 * s.median, 100 * p95,
                100 * s.max, 100.0 * static_cast<double>(ok) / draws, 100 * cv.median, 100 * cv.min,
                100.0 * static_cast<double>(covered) / draws, misses_inside[c], misses[c]);
  }
  // The band on each channel's worst draw: where the estimate is off, is the truth inside?
  for (std::size_t c = 0; c < 3; ++c) {
    const int seed = worst_seed[c];
    std::mt19937 rng(static_cast<unsigned>(seed));
    std::normal_distribution<double> nd(0, 1);
    Eigen::MatrixXd raw = clean;
    for (Eigen::Index i = 0; i < raw.rows(); ++i)
      for (int k = 0; k < 3; ++k) raw(i, k) *= 1 + noise * nd(rng);
    const auto m = ca::fit_blackbox(spectra, raw, o);
    const auto ci = static_cast<Eigen::Index>(c);
    const auto band = ca::credible_band(m.sensitivities.row(ci).transpose(), m.sensitivity_sdev.row(ci).transpose());
    const double peak = truth.row(ci).maxCoeff();
    std::printf("\n%c on its worst draw (seed %d), %% of the true peak:\n\n| nm | truth | estimate | 95 %% band | |\n|---|---|---|---|---|\n",
                "RGB"[c], seed);
    for (Eigen::Index k = 0; k < band.lower.size(); ++k) {
      const bool in = truth(ci, k) >= band.lower(k) && truth(ci, k) <= band.upper(k);
      const bool miss = std::abs(m.sensitivities(ci, k) - truth(ci, k)) > 0.10 * peak;
      std::printf("| %.0f | %.1f | %.1f | %.1f – %.1f | %s%s |\n", cams.wavelengths[static_cast<std::size_t>(k)], 100 * truth(ci, k) / peak,
                  100 * m.sensitivities(ci, k) / peak, 100 * band.lower(k) / peak, 100 * band.upper(k) / peak, miss ? "off > 10 %" : "",
                  in ? "" : (miss ? ", outside band" : "outside band"));
    }
  }
  return 0;
}
