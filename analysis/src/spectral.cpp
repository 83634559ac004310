#include "colorlab/analysis/spectral.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "parse_util.hpp"

namespace colorlab::analysis {

std::optional<std::size_t> SpectralSet::index_of(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return i;
  return std::nullopt;
}

std::size_t SpectralSet::require(const std::string& name) const {
  auto i = index_of(name);
  if (!i) detail::fail(source + ": no sample named '" + name + "'");
  return *i;
}

SpectralSet SpectralSet::select(const std::vector<std::size_t>& rows) const {
  SpectralSet out;
  out.wavelengths = wavelengths;
  out.source = source;
  out.values.resize(static_cast<Eigen::Index>(rows.size()), values.cols());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i] >= size()) detail::fail(source + ": sample index " + std::to_string(rows[i]) + " out of range");
    out.values.row(static_cast<Eigen::Index>(i)) = values.row(static_cast<Eigen::Index>(rows[i]));
    out.names.push_back(names[rows[i]]);
  }
  return out;
}

void SpectralSet::check_shape() const {
  if (wavelengths.size() < 2) detail::fail(source + ": a spectrum needs at least 2 wavelengths");
  if (static_cast<std::size_t>(values.cols()) != wavelengths.size())
    detail::fail(source + ": " + std::to_string(values.cols()) + " values per spectrum but " +
                 std::to_string(wavelengths.size()) + " wavelengths");
  if (names.size() != size()) detail::fail(source + ": names and spectra differ in number");
  for (std::size_t i = 1; i < wavelengths.size(); ++i)
    if (!(wavelengths[i] > wavelengths[i - 1]))
      detail::fail(source + ": wavelengths not strictly increasing at " + std::to_string(wavelengths[i]) + " nm");
}

std::vector<double> uniform_grid(double start, double end, double step) {
  if (!(step > 0) || !(end >= start) || !std::isfinite(start) || !std::isfinite(end))
    throw Error(ErrorClass::bad_parameter, "invalid wavelength grid " + std::to_string(start) + ".." +
                                               std::to_string(end) + " step " + std::to_string(step));
  std::vector<double> g;
  const auto n = static_cast<std::size_t>(std::floor((end - start) / step + 1e-9)) + 1;
  for (std::size_t i = 0; i < n; ++i) g.push_back(start + static_cast<double>(i) * step);
  return g;
}

bool sprague_applicable(const std::vector<double>& x) {
  if (x.size() < 6) return false;
  const double h = x[1] - x[0];
  for (std::size_t i = 1; i < x.size(); ++i)
    if (std::abs((x[i] - x[i - 1]) - h) > 1e-6 * h) return false;
  return h > 0;
}

namespace {

// Natural cubic spline through the unit vector e_j gives column j of the resampling matrix; solving the
// tridiagonal system for all columns at once keeps it O(n²) for the setup.
Eigen::MatrixXd spline_matrix(const std::vector<double>& x, const std::vector<double>& to) {
  const auto n = static_cast<Eigen::Index>(x.size());
  // Second derivatives M = A⁻¹ B y with natural end conditions.
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n), B = Eigen::MatrixXd::Zero(n, n);
  A(0, 0) = 1;
  A(n - 1, n - 1) = 1;
  for (Eigen::Index i = 1; i + 1 < n; ++i) {
    double h0 = x[i] - x[i - 1], h1 = x[i + 1] - x[i];
    A(i, i - 1) = h0 / 6;
    A(i, i) = (h0 + h1) / 3;
    A(i, i + 1) = h1 / 6;
    B(i, i - 1) = 1 / h0;
    B(i, i) = -1 / h0 - 1 / h1;
    B(i, i + 1) = 1 / h1;
  }
  Eigen::MatrixXd M = A.partialPivLu().solve(B);  // n×n: second derivatives per unit input
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(to.size()), n);
  for (std::size_t k = 0; k < to.size(); ++k) {
    auto it = std::upper_bound(x.begin(), x.end(), to[k]);
    Eigen::Index i = std::clamp<Eigen::Index>(static_cast<Eigen::Index>(it - x.begin()) - 1, 0, n - 2);
    double h = x[i + 1] - x[i];
    double a = (x[i + 1] - to[k]) / h, b = (to[k] - x[i]) / h;
    auto row = R.row(static_cast<Eigen::Index>(k));
    row(i) += a;
    row(i + 1) += b;
    row += ((a * a * a - a) * h * h / 6) * M.row(i) + ((b * b * b - b) * h * h / 6) * M.row(i + 1);
  }
  return R;
}

Eigen::MatrixXd linear_matrix(const std::vector<double>& x, const std::vector<double>& to) {
  const auto n = static_cast<Eigen::Index>(x.size());
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(to.size()), n);
  for (std::size_t k = 0; k < to.size(); ++k) {
    auto it = std::upper_bound(x.begin(), x.end(), to[k]);
    Eigen::Index i = std::clamp<Eigen::Index>(static_cast<Eigen::Index>(it - x.begin()) - 1, 0, n - 2);
    double t = (to[k] - x[i]) / (x[i + 1] - x[i]);
    R(static_cast<Eigen::Index>(k), i) = 1 - t;
    R(static_cast<Eigen::Index>(k), i + 1) = t;
  }
  return R;
}

// Sprague (1880) quintic as given in CIE 167:2005, with the CIE's two extrapolated points at each end.
Eigen::MatrixXd sprague_matrix(const std::vector<double>& x, const std::vector<double>& to) {
  const auto n = static_cast<Eigen::Index>(x.size());
  if (n < 6) detail::fail("Sprague interpolation needs at least 6 samples, got " + std::to_string(n));
  const double h = x[1] - x[0];
  for (Eigen::Index i = 1; i < n; ++i)
    if (std::abs((x[i] - x[i - 1]) - h) > 1e-6 * h)
      detail::fail("Sprague interpolation needs a uniform grid; step changes at " + std::to_string(x[i]) + " nm");
  // Extended samples e (n+4) as linear combinations of the n inputs.
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n + 4, n);
  const double c[4][6] = {{884, -1960, 3033, -2648, 1080, -180},
                          {508, -540, 488, -367, 144, -24},
                          {-24, 144, -367, 488, -540, 508},
                          {-180, 1080, -2648, 3033, -1960, 884}};
  for (int j = 0; j < 6; ++j) {
    E(0, j) = c[0][j] / 209;
    E(1, j) = c[1][j] / 209;
    E(n + 2, n - 6 + j) = c[2][j] / 209;
    E(n + 3, n - 6 + j) = c[3][j] / 209;
  }
  for (Eigen::Index i = 0; i < n; ++i) E(i + 2, i) = 1;
  Eigen::MatrixXd R(static_cast<Eigen::Index>(to.size()), n);
  for (std::size_t k = 0; k < to.size(); ++k) {
    Eigen::Index i = std::clamp<Eigen::Index>(static_cast<Eigen::Index>(std::floor((to[k] - x[0]) / h)), 0, n - 2);
    double t = (to[k] - x[i]) / h;
    // Rows of E for f_{i-2} .. f_{i+3} sit at i .. i+5 in the extended vector.
    auto f = [&](int off) { return E.row(i + 2 + off); };
    Eigen::RowVectorXd a0 = f(0);
    Eigen::RowVectorXd a1 = (2 * f(-2) - 16 * f(-1) + 16 * f(1) - 2 * f(2)) / 24;
    Eigen::RowVectorXd a2 = (-f(-2) + 16 * f(-1) - 30 * f(0) + 16 * f(1) - f(2)) / 24;
    Eigen::RowVectorXd a3 = (-9 * f(-2) + 39 * f(-1) - 70 * f(0) + 66 * f(1) - 33 * f(2) + 7 * f(3)) / 24;
    Eigen::RowVectorXd a4 = (13 * f(-2) - 64 * f(-1) + 126 * f(0) - 124 * f(1) + 61 * f(2) - 12 * f(3)) / 24;
    Eigen::RowVectorXd a5 = (-5 * f(-2) + 25 * f(-1) - 50 * f(0) + 50 * f(1) - 25 * f(2) + 5 * f(3)) / 24;
    R.row(static_cast<Eigen::Index>(k)) = a0 + t * (a1 + t * (a2 + t * (a3 + t * (a4 + t * a5))));
  }
  return R;
}

}  // namespace

Eigen::MatrixXd resampling_matrix(const std::vector<double>& from, const std::vector<double>& to, Interpolation method) {
  if (from.size() < 2) detail::fail("resampling needs at least 2 source wavelengths");
  for (std::size_t i = 1; i < from.size(); ++i)
    if (!(from[i] > from[i - 1])) detail::fail("source wavelengths not strictly increasing at " + std::to_string(from[i]));
  const double tol = 1e-9 * (from.back() - from.front());
  for (double w : to)
    if (!std::isfinite(w) || w < from.front() - tol || w > from.back() + tol) {
      std::ostringstream os;
      os << "cannot resample to " << w << " nm: data cover only " << from.front() << "-" << from.back() << " nm";
      detail::fail(os.str(), "restrict the target grid to the measured range");
    }
  switch (method) {
    case Interpolation::linear: return linear_matrix(from, to);
    case Interpolation::cubic_spline: return spline_matrix(from, to);
    case Interpolation::sprague: return sprague_matrix(from, to);
  }
  throw Error(ErrorClass::internal, "unknown interpolation");
}

SpectralSet resample(const SpectralSet& set, const std::vector<double>& to, Interpolation method) {
  set.check_shape();
  SpectralSet out = set;
  out.wavelengths = to;
  out.values = set.values * resampling_matrix(set.wavelengths, to, method).transpose();
  return out;
}

SpectralSet spectra_from_cgats(const CgatsTable& t) {
  SpectralSet s;
  s.source = t.source;
  std::vector<std::size_t> cols;
  for (std::size_t i = 0; i < t.fields.size(); ++i) {
    const auto& f = t.fields[i];
    if (f.rfind("SPEC_", 0) != 0) continue;
    auto wl = detail::to_double(std::string_view(f).substr(5));
    if (!wl) detail::fail(t.source + ": field " + f + " does not name a wavelength");
    s.wavelengths.push_back(*wl);
    cols.push_back(i);
  }
  if (cols.empty()) detail::fail(t.source + ": no SPEC_ fields: not a spectral CGATS file");
  // The START/END/BANDS keywords are authoritative: some writers mangle field names (colord's CIE-A.sp names
  // 300.000 nm "SPEC_300000").
  auto kw = [&](const char* k) -> std::optional<double> {
    auto v = t.keyword(k);
    return v ? detail::to_double(*v) : std::nullopt;
  };
  auto start = kw("SPECTRAL_START_NM"), end = kw("SPECTRAL_END_NM"), bands = kw("SPECTRAL_BANDS");
  if (start && end && bands) {
    if (static_cast<std::size_t>(*bands) != cols.size())
      detail::fail(t.source + ": SPECTRAL_BANDS says " + std::to_string(static_cast<long>(*bands)) + " but there are " +
                   std::to_string(cols.size()) + " SPEC_ fields");
    if (cols.size() > 1) {
      const double step = (*end - *start) / static_cast<double>(cols.size() - 1);
      for (std::size_t i = 0; i < cols.size(); ++i) s.wavelengths[i] = *start + step * static_cast<double>(i);
    }
  }
  double norm = 1.0;
  if (auto n = t.keyword("SPECTRAL_NORM")) {
    auto v = detail::to_double(*n);
    if (!v || !(*v > 0)) detail::fail(t.source + ": SPECTRAL_NORM '" + *n + "' is not a positive number");
    norm = *v;
  }
  std::optional<std::size_t> id = t.field_index("SAMPLE_ID");
  if (!id) id = t.field_index("SAMPLE_NAME");
  if (!id) id = t.field_index("SAMPLE_LOC");
  const std::string base = t.keyword("DISPLAY").value_or("sample");
  s.values.resize(static_cast<Eigen::Index>(t.rows.size()), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    s.names.push_back(id ? t.rows[r][*id] : (t.rows.size() == 1 ? base : base + "_" + std::to_string(r + 1)));
    for (std::size_t c = 0; c < cols.size(); ++c)
      s.values(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = t.number(r, cols[c]) / norm;
  }
  s.check_shape();
  return s;
}

SpectralSet spectra_from_csv(const CsvTable& t) {
  const std::string& h0 = t.header.at(0);
  if (h0 != "wavelength_nm" && h0 != "nm" && h0 != "wavelength" && h0 != "lambda")
    detail::fail(t.source + ": first column must be wavelength_nm, found '" + h0 + "'");
  if (t.header.size() < 2) detail::fail(t.source + ": no spectra columns");
  if (t.rows.size() < 2) detail::fail(t.source + ": fewer than 2 wavelength rows");
  SpectralSet s;
  s.source = t.source;
  for (std::size_t c = 1; c < t.header.size(); ++c) s.names.push_back(t.header[c]);
  s.values.resize(static_cast<Eigen::Index>(t.header.size() - 1), static_cast<Eigen::Index>(t.rows.size()));
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    s.wavelengths.push_back(t.number(r, 0));
    for (std::size_t c = 1; c < t.header.size(); ++c)
      s.values(static_cast<Eigen::Index>(c - 1), static_cast<Eigen::Index>(r)) = t.number(r, c);
  }
  s.check_shape();
  return s;
}

SpectralSet read_spectra(const std::filesystem::path& path) {
  std::string text = read_text_file(path);
  std::size_t first = text.find_first_not_of(" \t\r\n");
  std::size_t eol = text.find('\n', first == std::string::npos ? 0 : first);
  std::string_view first_line = std::string_view(text).substr(first == std::string::npos ? 0 : first,
                                                              eol == std::string::npos ? std::string::npos : eol - first);
  if (first_line.find(',') != std::string_view::npos) return spectra_from_csv(parse_csv(text, path.string()));
  return spectra_from_cgats(parse_cgats(text, path.string()).front());
}

namespace {
void validate(const SpectralSet& set, double lo, double hi, const char* kind) {
  set.check_shape();
  for (Eigen::Index r = 0; r < set.values.rows(); ++r)
    for (Eigen::Index c = 0; c < set.values.cols(); ++c) {
      double v = set.values(r, c);
      if (!std::isfinite(v) || v < lo || v > hi) {
        std::ostringstream os;
        os << set.source << ": " << kind << " '" << set.names[static_cast<std::size_t>(r)] << "' at "
           << set.wavelengths[static_cast<std::size_t>(c)] << " nm is " << v
           << (std::isfinite(v) ? (v < lo ? " (negative)" : " (implausibly large)") : " (not finite)");
        detail::fail(os.str());
      }
    }
}
}  // namespace

void validate_reflectance(const SpectralSet& set, double tolerance) {
  validate(set, -tolerance, 1.5, "reflectance");
}
void validate_emission(const SpectralSet& set, double tolerance) {
  validate(set, -tolerance, std::numeric_limits<double>::max(), "emission spectrum");
}

}  // namespace colorlab::analysis
