#pragma once
// Spectral sample sets on a wavelength grid, their readers and resampling.
#include <Eigen/Dense>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "colorlab/analysis/cgats.hpp"
#include "colorlab/analysis/csv.hpp"

namespace colorlab::analysis {

// One or more spectra sharing one wavelength grid (rows = samples, columns = wavelengths).
struct SpectralSet {
  std::vector<double> wavelengths;  // nm, strictly increasing
  std::vector<std::string> names;   // one per sample
  Eigen::MatrixXd values;
  std::string source;

  std::size_t size() const { return static_cast<std::size_t>(values.rows()); }
  std::size_t bands() const { return wavelengths.size(); }
  std::optional<std::size_t> index_of(const std::string& name) const;
  std::size_t require(const std::string& name) const;  // throws Error(bad_data)
  SpectralSet select(const std::vector<std::size_t>& rows) const;
  // Throws Error(bad_data) on a shape mismatch or an unsorted grid.
  void check_shape() const;
};

enum class Interpolation {
  linear,        // lamps with line spectra: never invents overshoot between tabulated lines
  cubic_spline,  // natural cubic spline, any grid
  sprague,       // CIE 167:2005 recommendation; needs a uniform source grid with at least 6 points
};

std::vector<double> uniform_grid(double start_nm, double end_nm, double step_nm);
// Sprague needs a uniform grid of at least 6 samples.
bool sprague_applicable(const std::vector<double>& grid);

// Matrix R (to.size() × from.size()) with resampled = R · values, so that a resampling is computed once and
// applied to many spectra. Target points must lie inside [from.front(), from.back()].
Eigen::MatrixXd resampling_matrix(const std::vector<double>& from, const std::vector<double>& to, Interpolation method);
SpectralSet resample(const SpectralSet& set, const std::vector<double>& to, Interpolation method);

// SPEC_nnn fields (divided by SPECTRAL_NORM when present); names from SAMPLE_ID / SAMPLE_NAME / SAMPLE_LOC.
SpectralSet spectra_from_cgats(const CgatsTable& table);
// First column wavelength_nm (or "nm"/"wavelength"), one column per sample.
SpectralSet spectra_from_csv(const CsvTable& table);
// CGATS or CSV, decided by content.
SpectralSet read_spectra(const std::filesystem::path& path);

// Reflectances must be finite and within [-tolerance, 1.5] (fluorescent whites exceed 1 slightly).
void validate_reflectance(const SpectralSet& set, double tolerance = 1e-6);
// Emission / illuminant spectra must be finite and non-negative.
void validate_emission(const SpectralSet& set, double tolerance = 1e-9);

}  // namespace colorlab::analysis
