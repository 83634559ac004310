#include "colorlab/analysis/chart_io.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <sstream>

#include "colorlab/core/error.hpp"
#include "parse_util.hpp"

namespace colorlab::analysis {

std::string sg_patch_id(int n) {
  if (n < 1 || n > 140) throw Error(ErrorClass::bad_parameter, "SG patch number must be 1-140, got " + std::to_string(n));
  return std::string(1, static_cast<char>('A' + (n - 1) % 14)) + std::to_string((n - 1) / 14 + 1);
}

int sg_patch_number(const std::string& id) {
  if (id.size() < 2 || id[0] < 'A' || id[0] > 'N') throw Error(ErrorClass::bad_parameter, "'" + id + "' is not an SG patch id");
  int row = 0;
  try {
    row = std::stoi(id.substr(1));
  } catch (const std::exception&) {
    row = 0;
  }
  if (row < 1 || row > 10) throw Error(ErrorClass::bad_parameter, "'" + id + "' is not an SG patch id");
  return (row - 1) * 14 + (id[0] - 'A') + 1;
}

namespace {
std::string fmt(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

// Argyll types a non-standard field (SPEC_*) by its values: a real needs its decimal point ("7" is an
// integer and spec2cie refuses it). Six decimals are far below any instrument's resolution on 0–100.
std::string real(double v) {
  std::array<char, 400> buf{};
  auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v, std::chars_format::fixed, 6);
  if (ec != std::errc()) detail::fail("CGATS: value " + fmt(v) + " cannot be written");
  return std::string(buf.data(), end);
}

void complete(ChartData& d, bool have_xyz, bool have_lab, const std::string& src) {
  const auto n = static_cast<Eigen::Index>(d.ids.size());
  if (!have_xyz && !have_lab) detail::fail(src + ": needs X,Y,Z or L,a,b columns for the reference colours");
  if (!have_lab) d.lab = xyz_rows_to_lab(d.xyz, d.white);
  if (!have_xyz) {
    d.xyz.resize(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) {
      Xyz x = lab_to_xyz({d.lab(i, 0), d.lab(i, 1), d.lab(i, 2)}, d.white);
      d.xyz.row(i) << x.X, x.Y, x.Z;
    }
  }
  d.check();
}
}  // namespace

ChartData read_chart(const std::filesystem::path& path, const Xyz& white) {
  std::string text = read_text_file(path);
  ChartData d;
  d.white = white;
  std::size_t first = text.find_first_not_of(" \t\r\n");
  std::size_t eol = text.find('\n', first == std::string::npos ? 0 : first);
  bool csv = first != std::string::npos && text.substr(first, eol - first).find(',') != std::string::npos;
  if (csv) {
    CsvTable t = parse_csv(text, path.string());
    auto col = [&](std::initializer_list<const char*> names) -> std::optional<std::size_t> {
      for (const char* n : names)
        if (auto c = t.column(n)) return c;
      return std::nullopt;
    };
    auto id = col({"patch_id", "id", "SAMPLE_ID", "patch"});
    auto r = col({"R", "r", "RGB_R"}), g = col({"G", "g", "RGB_G"}), b = col({"B", "b_rgb", "RGB_B"});
    if (!r || !g || !b) detail::fail(path.string() + ": needs R, G, B columns");
    auto X = col({"X", "X_D50", "XYZ_X"}), Y = col({"Y", "Y_D50", "XYZ_Y"}), Z = col({"Z", "Z_D50", "XYZ_Z"});
    auto L = col({"L", "L_D50", "LAB_L"}), A = col({"a", "a_D50", "LAB_A"}), B = col({"b", "b_D50", "LAB_B"});
    const auto n = static_cast<Eigen::Index>(t.rows.size());
    if (n == 0) detail::fail(path.string() + ": no patch rows");
    d.rgb.resize(n, 3);
    d.xyz.resize(n, 3);
    d.lab.resize(n, 3);
    bool hx = X && Y && Z, hl = L && A && B;
    for (Eigen::Index i = 0; i < n; ++i) {
      auto row = static_cast<std::size_t>(i);
      d.ids.push_back(id ? t.rows[row][*id] : std::to_string(i + 1));
      d.rgb.row(i) << t.number(row, *r), t.number(row, *g), t.number(row, *b);
      if (hx) d.xyz.row(i) << t.number(row, *X), t.number(row, *Y), t.number(row, *Z);
      if (hl) d.lab.row(i) << t.number(row, *L), t.number(row, *A), t.number(row, *B);
    }
    complete(d, hx, hl, path.string());
    return d;
  }
  CgatsTable t = parse_cgats(text, path.string()).front();
  auto has = [&](const char* f) { return t.field_index(f).has_value(); };
  if (!has("RGB_R") || !has("RGB_G") || !has("RGB_B")) detail::fail(path.string() + ": no RGB_R/RGB_G/RGB_B fields");
  auto id = t.field_index("SAMPLE_ID");
  if (!id) id = t.field_index("SAMPLE_LOC");
  const auto n = static_cast<Eigen::Index>(t.rows.size());
  d.rgb.resize(n, 3);
  d.xyz.resize(n, 3);
  d.lab.resize(n, 3);
  bool hx = has("XYZ_X") && has("XYZ_Y") && has("XYZ_Z"), hl = has("LAB_L") && has("LAB_A") && has("LAB_B");
  for (Eigen::Index i = 0; i < n; ++i) {
    auto row = static_cast<std::size_t>(i);
    d.ids.push_back(id ? t.rows[row][*id] : std::to_string(i + 1));
    d.rgb.row(i) << t.number(row, "RGB_R") / 100, t.number(row, "RGB_G") / 100, t.number(row, "RGB_B") / 100;
    if (hx) d.xyz.row(i) << t.number(row, "XYZ_X"), t.number(row, "XYZ_Y"), t.number(row, "XYZ_Z");
    if (hl) d.lab.row(i) << t.number(row, "LAB_L"), t.number(row, "LAB_A"), t.number(row, "LAB_B");
  }
  complete(d, hx, hl, path.string());
  return d;
}

CgatsTable argyll_ti3_table(const ChartData& chart, const SpectralSet* spectra, const Ti3Options& o) {
  chart.check();
  if (spectra && spectra->size() != chart.size())
    detail::fail("ti3: " + std::to_string(spectra->size()) + " spectra for " + std::to_string(chart.size()) + " patches");
  if (o.device_class != "INPUT" && o.device_class != "OUTPUT")
    throw Error(ErrorClass::bad_parameter, "ti3: device class must be INPUT or OUTPUT, not " + o.device_class);
  CgatsTable t;
  t.file_type = "CTI3";
  // Argyll names the colour spaces in the direction its profile maps: PCS from device for an input.
  t.keywords = {
      {"DESCRIPTOR", o.descriptor},
      {"ORIGINATOR", "colorlab"},
      {"DEVICE_CLASS", o.device_class},
      {"COLOR_REP", o.device_class == "INPUT" ? "XYZ_RGB" : "RGB_XYZ"},
  };
  t.fields = {"SAMPLE_ID", "RGB_R", "RGB_G", "RGB_B", "XYZ_X", "XYZ_Y", "XYZ_Z"};
  if (o.with_lab) t.fields.insert(t.fields.end(), {"LAB_L", "LAB_A", "LAB_B"});
  if (spectra) {
    spectra->check_shape();
    t.keywords.emplace_back("SPECTRAL_BANDS", std::to_string(spectra->bands()));
    t.keywords.emplace_back("SPECTRAL_START_NM", real(spectra->wavelengths.front()));
    t.keywords.emplace_back("SPECTRAL_END_NM", real(spectra->wavelengths.back()));
    t.keywords.emplace_back("SPECTRAL_NORM", real(100));
    for (double w : spectra->wavelengths) t.fields.push_back("SPEC_" + std::to_string(static_cast<int>(std::lround(w))));
  }
  t.keywords.insert(t.keywords.end(), o.keywords.begin(), o.keywords.end());
  for (std::size_t i = 0; i < chart.size(); ++i) {
    auto r = static_cast<Eigen::Index>(i);
    std::vector<std::string> row{chart.ids[i]};
    for (int c = 0; c < 3; ++c) row.push_back(real(chart.rgb(r, c) * 100));
    for (int c = 0; c < 3; ++c) row.push_back(real(chart.xyz(r, c)));
    if (o.with_lab)
      for (int c = 0; c < 3; ++c) row.push_back(real(chart.lab(r, c)));
    if (spectra)
      for (Eigen::Index k = 0; k < spectra->values.cols(); ++k) row.push_back(real(spectra->values(r, k) * 100));
    t.rows.push_back(std::move(row));
  }
  return t;
}

std::string format_argyll_ti3(const ChartData& chart, const SpectralSet* spectra, const Ti3Options& options) {
  return format_cgats(argyll_ti3_table(chart, spectra, options));
}

void write_argyll_ti3(const std::filesystem::path& path, const ChartData& chart, const SpectralSet* spectra) {
  write_cgats(argyll_ti3_table(chart, spectra), path);
}

void write_spectra_cgats(const std::filesystem::path& path, const SpectralSet& s, const std::string& file_type) {
  s.check_shape();
  CgatsTable t;
  t.file_type = file_type;
  t.keywords = {
      {"DESCRIPTOR", "colorlab spectra"},
      {"ORIGINATOR", "colorlab"},
      {"SPECTRAL_BANDS", std::to_string(s.bands())},
      {"SPECTRAL_START_NM", fmt(s.wavelengths.front())},
      {"SPECTRAL_END_NM", fmt(s.wavelengths.back())},
      {"SPECTRAL_NORM", "100.0"},
  };
  t.fields = {"SAMPLE_ID"};
  for (double w : s.wavelengths) t.fields.push_back("SPEC_" + std::to_string(static_cast<int>(std::lround(w))));
  for (std::size_t i = 0; i < s.size(); ++i) {
    std::vector<std::string> row{s.names[i]};
    for (Eigen::Index k = 0; k < s.values.cols(); ++k) row.push_back(real(s.values(static_cast<Eigen::Index>(i), k) * 100));
    t.rows.push_back(std::move(row));
  }
  write_cgats(t, path);
}

}  // namespace colorlab::analysis
