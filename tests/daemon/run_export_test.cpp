// The export conversions on their own (run_export.hpp): formats and names, CSV and JSON bodies, and the
// two kinds of .ti3 built from measurement values, read back by the project's CGATS and CSV readers.
#include <gtest/gtest.h>

#include "colorlab/analysis/cgats.hpp"
#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/csv.hpp"
#include "colorlab/core/error.hpp"
#include "run_export.hpp"

namespace rx = colorlab::daemon::run_export;
namespace ca = colorlab::analysis;
using colorlab::ErrorClass;
using colorlab::store::MeasurementRecord;
using colorlab::store::RunRecord;
using nlohmann::json;

namespace {

RunRecord run(const std::string& campaign) {
  RunRecord r;
  r.id = "0190f3e1-0000-7000-8000-000000000001";
  r.campaign = campaign;
  r.status = "finished_ok";
  r.simulated = true;
  r.created_at = "2026-11-23T01:02:03.000Z";
  r.params = json::object();
  return r;
}

MeasurementRecord patch(std::int64_t seq, const std::string& id, int index, std::array<double, 3> xyz) {
  MeasurementRecord m;
  m.seq = seq;
  m.step = "patch/" + id;
  m.instrument_id = "spectrolino";
  m.quantity = "reflectance_spectrum";
  m.unit = "L*";
  const auto lab = ca::xyz_to_lab({xyz[0], xyz[1], xyz[2]}, ca::kIccD50White);
  m.value = lab.L;
  // A flat reflectance of Y/100 on 380–730 nm at 10 nm.
  m.data = {
      {"id", id},
      {"index", index},
      {"XYZ", xyz},
      {"Lab", {lab.L, lab.a, lab.b}},
      {"first_nm", 380},
      {"step_nm", 10},
      {"values", std::vector<double>(36, xyz[1] / 100)},
  };
  return m;
}

MeasurementRecord camera(std::int64_t seq, const std::string& id, std::array<double, 3> rgb, const std::string& unit) {
  MeasurementRecord m;
  m.seq = seq;
  m.step = "patch/raw/" + id;
  m.quantity = "camera_rgb";
  m.unit = unit;
  m.value = rgb[1];
  m.data = {{"id", id}, {"format", "raw"}, {"rgb", rgb}};
  return m;
}

template <typename F>
void expect_error(F&& f, ErrorClass cls, const std::string& needle) {
  try {
    f();
    FAIL() << "no error: " << needle;
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), cls) << e.what();
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(RunExport, FormatsFromTheQueryOrTheAcceptHeader) {
  EXPECT_EQ(rx::parse_format("ti3"), rx::Format::ti3);
  expect_error([] { rx::parse_format("xlsx"); }, ErrorClass::bad_parameter, "ti3, csv or json");
  EXPECT_EQ(rx::format_for_accept("image/png, text/csv;q=0.9"), rx::Format::csv);
  EXPECT_EQ(rx::format_for_accept("TEXT/X-CGATS"), rx::Format::ti3);
  EXPECT_EQ(rx::format_for_accept("*/*"), rx::Format::json);
  EXPECT_FALSE(rx::format_for_accept("image/png").has_value());
  RunRecord r = run("my campaign/x");
  EXPECT_EQ(rx::file_name(r, rx::Format::csv), "my_campaign_x-0190f3e1-0000-7000-8000-000000000001.csv");
  EXPECT_EQ(rx::file_name(r, rx::Format::ti3, "raw"), "my_campaign_x-0190f3e1-0000-7000-8000-000000000001-raw.ti3");
}

TEST(RunExport, CsvAndJsonHoldEveryMeasurementAsStored) {
  std::vector<MeasurementRecord> ms{patch(1, "A1", 0, {85.3, 88.9, 71.7}), patch(2, "B1", 1, {0.1 / 3, 1e-300, 2})};
  ms[1].value.reset();
  ms[1].step = "odd, \"step\"\nname";
  rx::CsvBody csv;
  rx::JsonBody js(run("chart-read"));
  for (const auto& m : ms) {
    csv.add(m);
    js.add(m);
  }
  const auto t = ca::parse_csv(csv.take(), "export.csv");
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[1][t.require_column("step")], ms[1].step);
  EXPECT_EQ(t.number(0, t.require_column("value")), *ms[0].value);
  EXPECT_EQ(t.rows[1][t.require_column("value")], "");
  EXPECT_EQ(json::parse(t.rows[1][t.require_column("data")]), ms[1].data);
  const json doc = json::parse(js.take());
  EXPECT_EQ(doc["run"]["id"], run("chart-read").id);
  ASSERT_EQ(doc["measurements"].size(), 2u);
  EXPECT_EQ(doc["measurements"][1], ms[1].to_json());
}

TEST(RunExport, ChartReadTi3InTheChartsOrderWithSpectraAndNominalRgb) {
  // Read in serpentine order: B1 first; the file lists A1 first.
  std::vector<MeasurementRecord> ms{patch(1, "B1", 1, {17.2, 17.9, 14.8}), patch(2, "A1", 0, {96.42, 100.0, 82.49})};
  const auto t = ca::parse_cgats(rx::reference_ti3(run("chart-read"), ms), "m.ti3").front();
  EXPECT_EQ(t.file_type, "CTI3");
  EXPECT_EQ(t.keyword("DEVICE_CLASS"), "OUTPUT");
  EXPECT_EQ(t.keyword("COLOR_REP"), "RGB_XYZ");
  EXPECT_EQ(t.keyword("SPECTRAL_BANDS"), "36");
  EXPECT_EQ(t.keyword("COLORLAB_RUN"), run("chart-read").id);
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0][0], "A1");
  // The D50 white is sRGB's white; reflectance in percent.
  for (const char* f : {"RGB_R", "RGB_G", "RGB_B"}) EXPECT_NEAR(t.number(0, f), 100, 0.05) << f;
  EXPECT_DOUBLE_EQ(t.number(0, "XYZ_Y"), 100);
  EXPECT_DOUBLE_EQ(t.number(1, "SPEC_380"), 17.9);
  EXPECT_EQ(t.rows[1][*t.field_index("SPEC_730")], "17.900000");  // Argyll types reals by their decimal point
  auto no_xyz = ms;
  no_xyz[0].data.erase("XYZ");
  expect_error([&] { rx::reference_ti3(run("chart-read"), no_xyz); }, ErrorClass::unsupported, "patch/B1 has no XYZ");
  // A patch on another grid leaves the spectra out rather than mixing grids.
  auto mixed = ms;
  mixed[0].data["step_nm"] = 5;
  EXPECT_FALSE(ca::parse_cgats(rx::reference_ti3(run("chart-read"), mixed), "m.ti3").front().keyword("SPECTRAL_BANDS"));
}

TEST(RunExport, CameraTi3PairsEachPatchWithTheReferenceAndScalesItsValues) {
  const json reference{{"run_id", "ref"},
                       {"ids", {"A1", "B1"}},
                       {"XYZ", {{96.42, 100.0, 82.49}, {17.2, 17.9, 14.8}}},
                       {"Lab", {{100, 0, 0}, {49.4, 0, 0}}},
                       {"wavelengths", {400, 500, 600}},
                       {"spectra", {{0.9, 0.9, 0.9}, {0.2, 0.2, 0.2}}}};
  RunRecord r = run("characterize-camera");
  r.summary = {{"script", {{"selected", {{"format", "raw"}}}}}};
  std::vector<MeasurementRecord> raw{camera(1, "B1", {400, 800, -3}, "DN above black"), camera(2, "A1", {2000, 4000, 1000}, "DN above black")};
  EXPECT_EQ(rx::default_camera_format(r, raw[0]), "raw");
  auto t = ca::parse_cgats(rx::camera_ti3(r, raw, reference, "raw"), "c.ti3").front();
  EXPECT_EQ(t.keyword("DEVICE_CLASS"), "INPUT");
  EXPECT_EQ(t.keyword("COLORLAB_RGB_FULL_SCALE"), "4000");
  EXPECT_EQ(t.rows[0][0], "B1");
  EXPECT_DOUBLE_EQ(t.number(0, "RGB_R"), 10);
  EXPECT_DOUBLE_EQ(t.number(0, "RGB_B"), 0);  // below black: noise, clamped to Argyll's range
  EXPECT_DOUBLE_EQ(t.number(1, "RGB_G"), 100);
  EXPECT_DOUBLE_EQ(t.number(0, "XYZ_X"), 17.2);
  EXPECT_DOUBLE_EQ(t.number(0, "SPEC_500"), 20);
  // 8-bit codes by their full scale.
  auto eight = raw;
  for (auto& m : eight) m.unit = "8-bit code";
  eight[1].data["rgb"] = {255, 51, 0};
  t = ca::parse_cgats(rx::camera_ti3(r, eight, reference, "raw"), "c.ti3").front();
  EXPECT_DOUBLE_EQ(t.number(1, "RGB_G"), 20);
  expect_error([&] { rx::camera_ti3(r, raw, reference, "jpeg"); }, ErrorClass::bad_parameter, "format 'jpeg'");
  auto stranger = raw;
  stranger[0].data["id"] = "Z9";
  expect_error([&] { rx::camera_ti3(r, stranger, reference, "raw"); }, ErrorClass::conflict, "no patch Z9");
}

}  // namespace
