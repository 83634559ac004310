#include "chart.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "colorlab/analysis/spectral.hpp"
#include "colorlab/core/data_paths.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::sim {
namespace {

constexpr double patch_pitch_mm = 19.0;
constexpr double patch_size_mm = 15.0;
constexpr double grid_x0_mm = (chart_width_mm - chart_columns * patch_pitch_mm) / 2.0;
constexpr double grid_y0_mm = (chart_height_mm - chart_rows * patch_pitch_mm) / 2.0;
constexpr double chart_start_nm = 380.0, chart_step_nm = 10.0;
constexpr std::size_t chart_samples = 36;  // 380..730

std::string patch_name(int column, int row) {
  return std::string(1, static_cast<char>('A' + column)) + std::to_string(row + 1);
}

ChartPatch make_patch(int column, int row) {
  ChartPatch p;
  p.name = patch_name(column, row);
  p.column = column;
  p.row = row;
  const double gap = (patch_pitch_mm - patch_size_mm) / 2.0;
  p.x_mm = grid_x0_mm + column * patch_pitch_mm + gap;
  p.y_mm = grid_y0_mm + row * patch_pitch_mm + gap;
  p.size_mm = patch_size_mm;
  return p;
}

Chart empty_chart(std::string source) {
  Chart c;
  c.source = std::move(source);
  for (int col = 0; col < chart_columns; ++col)
    for (int row = 0; row < chart_rows; ++row) c.patches.push_back(make_patch(col, row));
  return c;
}

void check_range(const Spectrum& s, const std::string& source, const std::string& patch) {
  if (s.start_nm > chart_start_nm + 1e-6 || s.end_nm() < 730.0 - 1e-6) {
    throw Error(ErrorClass::bad_data, source + ": spectra must cover 380–730 nm (patch " + patch + " covers " +
                                          std::to_string(s.start_nm) + "–" + std::to_string(s.end_nm()) + ")");
  }
  for (double v : s.values) {
    if (!std::isfinite(v) || v < -0.05 || v > 2.0) {
      throw Error(ErrorClass::bad_data, source + ": patch " + patch + " has a reflectance value out of range");
    }
  }
}

Chart from_spectral_set(const analysis::SpectralSet& set, const std::string& source) {
  // The chart's own grid is 380–730/10 nm (what the Spectrolino reports); other grids are resampled.
  const auto grid = analysis::uniform_grid(chart_start_nm, 730.0, chart_step_nm);
  if (set.wavelengths.empty() || set.wavelengths.front() > chart_start_nm + 1e-6 ||
      set.wavelengths.back() < 730.0 - 1e-6) {
    throw Error(ErrorClass::bad_data, source + ": chart spectra must cover 380–730 nm");
  }
  const auto on_grid = analysis::resample(set, grid, analysis::Interpolation::cubic_spline);
  // Argyll writes reflectance in percent when no SPECTRAL_NORM is given.
  const double scale = on_grid.values.maxCoeff() > 2.0 ? 0.01 : 1.0;
  Chart c = empty_chart(source);
  for (auto& p : c.patches) {
    const auto row = set.index_of(p.name);
    if (!row) throw Error(ErrorClass::bad_data, source + ": no spectrum for patch " + p.name);
    Spectrum s{chart_start_nm, chart_step_nm, std::vector<double>(grid.size())};
    for (std::size_t b = 0; b < grid.size(); ++b)
      s.values[b] = scale * on_grid.values(static_cast<Eigen::Index>(*row), static_cast<Eigen::Index>(b));
    check_range(s, source, p.name);
    p.reflectance = std::move(s);
  }
  return c;
}

double logistic(double x) { return 1.0 / (1.0 + std::exp(-x)); }

}  // namespace

std::optional<int> Chart::patch_at(double x_mm, double y_mm) const {
  const int col = static_cast<int>(std::floor((x_mm - grid_x0_mm) / patch_pitch_mm));
  const int row = static_cast<int>(std::floor((y_mm - grid_y0_mm) / patch_pitch_mm));
  if (col < 0 || col >= chart_columns || row < 0 || row >= chart_rows) return std::nullopt;
  const auto& p = patches[static_cast<std::size_t>(col * chart_rows + row)];
  if (x_mm < p.x_mm || x_mm >= p.x_mm + p.size_mm || y_mm < p.y_mm || y_mm >= p.y_mm + p.size_mm) return std::nullopt;
  return col * chart_rows + row;
}

std::optional<int> Chart::index_of(std::string_view name) const {
  for (std::size_t i = 0; i < patches.size(); ++i)
    if (patches[i].name == name) return static_cast<int>(i);
  return std::nullopt;
}

namespace detail {

Chart chart_from_file(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) {
    throw Error(ErrorClass::not_found, "chart file " + path.string() + " does not exist");
  }
  return from_spectral_set(analysis::read_spectra(path), path.string());
}

Chart synthetic_chart() {
  Chart c = empty_chart("synthetic");
  // Fixed seed: the synthetic chart is a property of the product, not of a scene.
  std::mt19937_64 rng(0x5347'4348'4152'54ull);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (auto& p : c.patches) {
    std::vector<double> v(chart_samples);
    const bool border = p.column == 0 || p.column == chart_columns - 1 || p.row == 0 || p.row == chart_rows - 1;
    const bool grey_ramp = p.row == 4 && p.column >= 2 && p.column <= 11;
    if (border || grey_ramp) {
      // The SG border alternates white, black and mid grey; its grey ramp runs across the middle.
      const int k = border ? (p.column + p.row) % 3 : 0;
      const double level = grey_ramp ? 0.03 + 0.85 * (p.column - 2) / 9.0 : (k == 0 ? 0.88 : k == 1 ? 0.03
                                                                                                    : 0.19);
      for (std::size_t i = 0; i < chart_samples; ++i) {
        const double nm = chart_start_nm + chart_step_nm * double(i);
        v[i] = level * (1.0 - 0.06 * std::exp(-(nm - 380.0) / 30.0));  // slight OBA-free blue drop
      }
    } else {
      // A smooth spectrum: a low floor, a broad band and a long-wave step, as pigments give.
      const double floor = 0.03 + 0.12 * u01(rng);
      const double band_amp = 0.6 * u01(rng), band_centre = 420 + 230 * u01(rng), band_width = 25 + 50 * u01(rng);
      const double step_amp = 0.7 * u01(rng), step_edge = 520 + 160 * u01(rng), step_width = 10 + 25 * u01(rng);
      for (std::size_t i = 0; i < chart_samples; ++i) {
        const double nm = chart_start_nm + chart_step_nm * double(i);
        const double r = floor + band_amp * std::exp(-0.5 * std::pow((nm - band_centre) / band_width, 2)) +
                         step_amp * logistic((nm - step_edge) / step_width);
        v[i] = std::clamp(r, 0.02, 0.92);
      }
    }
    p.reflectance = Spectrum{chart_start_nm, chart_step_nm, std::move(v)};
  }
  return c;
}

Chart load_chart(const SceneConfig& config) {
  if (config.force_synthetic_chart) return synthetic_chart();
  if (config.chart_file) return chart_from_file(*config.chart_file);
  if (auto shared = paths::shared_data_file("colorcheckersg_xrite_before_nov2014_dcamprof_10nm_380_730.csv")) {
    return chart_from_file(*shared);
  }
  return synthetic_chart();
}

}  // namespace detail
}  // namespace colorlab::sim
