#include "run_export.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <map>

#include "colorlab/analysis/chart_io.hpp"
#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/csv.hpp"
#include "colorlab/analysis/rgb_spaces.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::daemon::run_export {

namespace ca = colorlab::analysis;
using nlohmann::json;

namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  for (auto& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return std::string(s);
}

// A patch reading is refused for the .ti3 with what it lacks; the run stays exportable as CSV and JSON.
[[noreturn]] void not_exportable(const std::string& what) {
  throw Error(ErrorClass::unsupported, what, "export it as csv or json, which hold every measurement as stored");
}

std::array<double, 3> triple(const json& d, const char* key, const store::MeasurementRecord& m) {
  if (!d.is_object() || !d.contains(key) || !d[key].is_array() || d[key].size() != 3 || !d[key][0].is_number() ||
      !d[key][1].is_number() || !d[key][2].is_number()) {
    not_exportable("measurement " + m.step + " has no " + key + " triple in its data");
  }
  return {d[key][0].get<double>(), d[key][1].get<double>(), d[key][2].get<double>()};
}

std::string patch_id(const store::MeasurementRecord& m) {
  if (!m.data.is_object() || !m.data.contains("id") || !m.data["id"].is_string() || m.data["id"].get<std::string>().empty())
    not_exportable("measurement " + m.step + " names no patch id in its data");
  return m.data["id"].get<std::string>();
}

void size_chart(ca::ChartData& c, std::size_t n) {
  c.rgb.resize(static_cast<Eigen::Index>(n), 3);
  c.xyz.resize(static_cast<Eigen::Index>(n), 3);
  c.lab.resize(static_cast<Eigen::Index>(n), 3);
}

// Each patch's spectrum on the grid all of them share, or nullopt when one lacks it or sits on another grid.
std::optional<ca::SpectralSet> shared_grid_spectra(const std::vector<const store::MeasurementRecord*>& rows,
                                                   const std::vector<std::string>& ids) {
  ca::SpectralSet s;
  std::optional<std::pair<double, double>> grid;
  std::vector<std::vector<double>> values;
  for (const auto* m : rows) {
    const json& d = m->data;
    if (!d.contains("values") || !d["values"].is_array() || !d.contains("first_nm") || !d["first_nm"].is_number() ||
        !d.contains("step_nm") || !d["step_nm"].is_number())
      return std::nullopt;
    const std::pair<double, double> g{d["first_nm"].get<double>(), d["step_nm"].get<double>()};
    if (!grid) grid = g;
    std::vector<double> v;
    for (const auto& x : d["values"]) {
      if (!x.is_number()) return std::nullopt;
      v.push_back(x.get<double>());
    }
    if (g != *grid || (!values.empty() && v.size() != values.front().size())) return std::nullopt;
    values.push_back(std::move(v));
  }
  if (!grid || values.front().size() < 3 || !(grid->second > 0)) return std::nullopt;
  for (std::size_t k = 0; k < values.front().size(); ++k) s.wavelengths.push_back(grid->first + grid->second * static_cast<double>(k));
  s.names = ids;
  s.values.resize(static_cast<Eigen::Index>(values.size()), static_cast<Eigen::Index>(s.wavelengths.size()));
  for (std::size_t i = 0; i < values.size(); ++i)
    for (std::size_t k = 0; k < values[i].size(); ++k) s.values(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)) = values[i][k];
  return s;
}

std::vector<std::pair<std::string, std::string>> provenance(const store::RunRecord& run) {
  std::vector<std::pair<std::string, std::string>> k{{"CREATED", run.finished_at.value_or(run.created_at)},
                                                     {"COLORLAB_RUN", run.id},
                                                     {"COLORLAB_CAMPAIGN", run.campaign},
                                                     {"COLORLAB_SIMULATED", run.simulated ? "YES" : "NO"}};
  return k;
}

struct FormatInfo {
  Format format;
  std::string_view name;  // the query's value and the file's extension
  std::string_view media_type;
};
constexpr FormatInfo kFormats[] = {{Format::ti3, "ti3", "text/x-cgats"},
                                   {Format::csv, "csv", "text/csv; charset=utf-8; header=present"},
                                   {Format::json, "json", "application/json"}};

const FormatInfo& info(Format f) {
  for (const auto& k : kFormats)
    if (k.format == f) return k;
  throw Error(ErrorClass::internal, "export format without a table entry");
}

}  // namespace

Format parse_format(std::string_view name) {
  for (const auto& k : kFormats)
    if (k.name == name) return k.format;
  throw Error(ErrorClass::bad_parameter, "format must be ti3, csv or json, not '" + std::string(name) + "'",
              "e.g. GET /v1/runs/{id}/export?format=csv");
}

std::optional<Format> format_for_accept(std::string_view accept) {
  std::size_t pos = 0;
  while (pos <= accept.size()) {
    std::size_t comma = accept.find(',', pos);
    std::string_view range = accept.substr(pos, comma == std::string_view::npos ? std::string_view::npos : comma - pos);
    pos = comma == std::string_view::npos ? accept.size() + 1 : comma + 1;
    const std::string type = lower(trim(range.substr(0, range.find(';'))));
    if (type == "text/csv" || type == "text/*") return Format::csv;
    if (type == "application/json" || type == "application/*" || type == "*/*") return Format::json;
    if (type == "text/x-cgats" || type == "application/x-cgats") return Format::ti3;
  }
  return std::nullopt;
}

std::string media_type(Format f) { return std::string(info(f).media_type); }

std::string_view extension(Format f) { return info(f).name; }

std::string file_name(const store::RunRecord& run, Format f, std::string_view part) {
  std::string name = run.campaign + "-" + run.id;
  if (!part.empty()) name += "-" + std::string(part);
  for (auto& c : name) {
    const bool safe = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
    if (!safe) c = '_';
  }
  return name + "." + std::string(extension(f));
}

CsvBody::CsvBody() {
  ca::append_csv_row(text_, {"seq", "step", "instrument_id", "simulated", "quantity", "value", "unit", "measured_at", "data"});
}

void CsvBody::add(const store::MeasurementRecord& m) {
  ca::append_csv_row(text_, {std::to_string(m.seq), m.step, m.instrument_id, m.simulated ? "true" : "false", m.quantity,
                             m.value ? ca::csv_number(*m.value) : "", m.unit, m.measured_at, m.data.is_null() ? "" : m.data.dump()});
}

JsonBody::JsonBody(const store::RunRecord& run) : text_("{\"run\":" + run.to_json().dump() + ",\"measurements\":[") {}

void JsonBody::add(const store::MeasurementRecord& m) {
  if (!first_) text_ += ',';
  first_ = false;
  text_ += m.to_json().dump();
}

std::string JsonBody::take() {
  text_ += "]}";
  return std::move(text_);
}

std::string reference_ti3(const store::RunRecord& run, const std::vector<store::MeasurementRecord>& patches) {
  if (patches.empty()) not_exportable("run " + run.id + " holds no patch readings");
  // The chart's own order (the table reads in serpentine rows) where every patch knows its index.
  std::vector<const store::MeasurementRecord*> rows;
  for (const auto& m : patches) rows.push_back(&m);
  const bool indexed = std::all_of(rows.begin(), rows.end(), [](const auto* m) { return m->data.is_object() && m->data.contains("index") && m->data["index"].is_number(); });
  if (indexed)
    std::stable_sort(rows.begin(), rows.end(), [](const auto* a, const auto* b) { return a->data["index"].template get<double>() < b->data["index"].template get<double>(); });
  ca::ChartData chart;
  size_chart(chart, rows.size());
  std::vector<ca::Xyz> xyz;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& m = *rows[i];
    chart.ids.push_back(patch_id(m));
    const auto x = triple(m.data, "XYZ", m);
    xyz.push_back({x[0], x[1], x[2]});
    const auto lab = m.data.contains("Lab") ? triple(m.data, "Lab", m) : [&] {
      const auto l = ca::xyz_to_lab(xyz.back(), ca::kIccD50White);
      return std::array<double, 3>{l.L, l.a, l.b};
    }();
    const auto r = static_cast<Eigen::Index>(i);
    chart.xyz.row(r) << x[0], x[1], x[2];
    chart.lab.row(r) << lab[0], lab[1], lab[2];
  }
  const auto srgb = ca::xyz_d50_to_rgb(ca::RgbSpace::srgb, xyz);
  for (std::size_t i = 0; i < srgb.size(); ++i)
    for (int c = 0; c < 3; ++c) chart.rgb(static_cast<Eigen::Index>(i), c) = std::clamp(srgb[i][static_cast<std::size_t>(c)], 0.0, 1.0);
  const auto spectra = shared_grid_spectra(rows, chart.ids);
  ca::Ti3Options o;
  o.descriptor = "colorlab " + run.campaign + " " + run.id + ": reference readings (RGB_* is each patch's colour in sRGB, no device)";
  o.device_class = "OUTPUT";
  o.with_lab = true;
  o.keywords = provenance(run);
  if (run.params.is_object() && run.params.contains("chart") && run.params["chart"].is_string())
    o.keywords.emplace_back("COLORLAB_CHART", run.params["chart"].get<std::string>());
  return ca::format_argyll_ti3(chart, spectra ? &*spectra : nullptr, o);
}

std::string default_camera_format(const store::RunRecord& run, const store::MeasurementRecord& first_patch) {
  const json* s = &run.summary;
  for (const char* key : {"script", "selected", "format"}) {
    if (!s->is_object() || !s->contains(key)) {
      s = nullptr;
      break;
    }
    s = &(*s)[key];
  }
  if (s && s->is_string()) return s->get<std::string>();
  if (first_patch.data.is_object() && first_patch.data.contains("format") && first_patch.data["format"].is_string())
    return first_patch.data["format"].get<std::string>();
  not_exportable("measurement " + first_patch.step + " names no camera format in its data");
}

std::string camera_ti3(const store::RunRecord& run, const std::vector<store::MeasurementRecord>& patches,
                       const json& reference, const std::string& camera_format) {
  std::vector<const store::MeasurementRecord*> rows;
  for (const auto& m : patches)
    if (m.data.is_object() && m.data.value("format", std::string()) == camera_format) rows.push_back(&m);
  if (rows.empty())
    throw Error(ErrorClass::bad_parameter, "run " + run.id + " holds no camera values in format '" + camera_format + "'",
                "camera_format names one of the formats the run photographed (raw, tiff16, tiff8, jpeg)");
  std::map<std::string, std::size_t> ref;
  for (std::size_t i = 0; i < reference.at("ids").size(); ++i) ref[reference["ids"][i].get<std::string>()] = i;
  // 8- and 16-bit codes have a full scale; raw counts above black have none recorded, so the largest is 100.
  const std::string unit = rows.front()->unit;
  double full = unit == "8-bit code" ? 255.0 : unit == "16-bit code" ? 65535.0
                                                                     : 0.0;
  std::vector<std::array<double, 3>> rgb;
  for (const auto* m : rows) {
    rgb.push_back(triple(m->data, "rgb", *m));
    if (unit != "8-bit code" && unit != "16-bit code") full = std::max({full, rgb.back()[0], rgb.back()[1], rgb.back()[2]});
  }
  if (!(full > 0)) not_exportable("run " + run.id + "'s " + camera_format + " values are all zero");
  ca::ChartData chart;
  size_chart(chart, rows.size());
  std::vector<std::size_t> ref_rows;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::string id = patch_id(*rows[i]);
    auto it = ref.find(id);
    if (it == ref.end())
      throw Error(ErrorClass::conflict, "the reference run " + reference.value("run_id", std::string()) + " has no patch " + id,
                  "the camera photographed another chart than the one read");
    chart.ids.push_back(id);
    ref_rows.push_back(it->second);
    const auto r = static_cast<Eigen::Index>(i);
    for (int c = 0; c < 3; ++c) {
      const auto k = static_cast<std::size_t>(c);
      // A count below black is noise on a black patch; Argyll takes device values on 0–100.
      chart.rgb(r, c) = std::clamp(rgb[i][k] / full, 0.0, 1.0);
      chart.xyz(r, c) = reference["XYZ"][it->second][k].get<double>();
      chart.lab(r, c) = reference["Lab"][it->second][k].get<double>();
    }
  }
  std::optional<ca::SpectralSet> spectra;
  if (reference.contains("spectra") && reference.contains("wavelengths")) {
    spectra.emplace();
    spectra->wavelengths = reference["wavelengths"].get<std::vector<double>>();
    spectra->names = chart.ids;
    spectra->values.resize(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(spectra->wavelengths.size()));
    for (std::size_t i = 0; i < ref_rows.size(); ++i) {
      const auto& v = reference["spectra"][ref_rows[i]];
      for (std::size_t k = 0; k < spectra->wavelengths.size(); ++k)
        spectra->values(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)) = v.at(k).get<double>();
    }
  }
  ca::Ti3Options o;
  o.descriptor = "colorlab " + run.campaign + " " + run.id + ": " + camera_format + " camera values of the chart read by " +
                 reference.value("run_id", std::string());
  o.device_class = "INPUT";
  o.with_lab = true;
  o.keywords = provenance(run);
  o.keywords.insert(o.keywords.end(), {{"COLORLAB_REFERENCE_RUN", reference.value("run_id", std::string())},
                                       {"COLORLAB_CAMERA_FORMAT", camera_format},
                                       {"COLORLAB_CAMERA_UNIT", unit},
                                       // RGB_* = 100 × camera value / this.
                                       {"COLORLAB_RGB_FULL_SCALE", ca::csv_number(full)}});
  return ca::format_argyll_ti3(chart, spectra ? &*spectra : nullptr, o);
}

}  // namespace colorlab::daemon::run_export
