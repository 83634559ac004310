#include "locate_chart_command.hpp"

#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "analyze_output.hpp"
#include "colorlab/analysis/chart_locate.hpp"
#include "colorlab/analysis/csv.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::cli::detail {
namespace {

namespace ca = colorlab::analysis;

struct LocateCliOptions {
  std::string photo, chart = "sg", corners, cfa, lens;
  double fraction = 0.6, black = 0, min_confidence = 0.6;
  int bits = 0;
  bool json = false;
};

// A list of numbers on the command line ("x1,y1,…"), read as one CSV row.
std::vector<double> numbers(const std::string& text, const std::string& what) {
  std::vector<double> v;
  for (const auto& cell : ca::parse_csv_row(text, what)) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(cell, &used));
      if (used != cell.size()) throw std::invalid_argument(cell);
    } catch (const std::exception&) {
      throw Error(ErrorClass::bad_parameter, what + ": '" + cell + "' is not a number");
    }
  }
  return v;
}

ca::CfaPattern parse_cfa(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (s == "rggb") return ca::CfaPattern::rggb;
  if (s == "bggr") return ca::CfaPattern::bggr;
  if (s == "grbg") return ca::CfaPattern::grbg;
  if (s == "gbrg") return ca::CfaPattern::gbrg;
  throw Error(ErrorClass::bad_parameter, "--cfa must be RGGB, BGGR, GRBG or GBRG, not '" + s + "'");
}

void run_locate(const LocateCliOptions& o) {
  const ca::ChartType type = ca::chart_type_from_string(o.chart);
  const ca::Photo photo = ca::read_photo(o.photo);
  ca::PhotoView view = photo.view();
  view.black_level = o.black;
  view.bit_depth = o.bits;
  if (!o.cfa.empty()) {
    if (photo.channels != 1)
      throw Error(ErrorClass::bad_parameter, "--cfa needs a one-channel raw mosaic (e.g. dcraw -D -4 -T), " + o.photo + " has 3 channels");
    view.cfa = parse_cfa(o.cfa);
  }
  ca::LocateOptions lo;
  lo.sample_fraction = o.fraction;
  lo.min_confidence = o.min_confidence;
  if (!o.corners.empty()) {
    const auto v = numbers(o.corners, "--corners");
    if (v.size() != 8) throw Error(ErrorClass::bad_parameter, "--corners needs 8 numbers x1,y1,…,x4,y4, got " + std::to_string(v.size()));
    std::array<ca::Point2, 4> c{};
    for (std::size_t i = 0; i < 4; ++i) c[i] = {v[2 * i], v[2 * i + 1]};
    lo.corners = c;
  }
  if (!o.lens.empty()) {
    const auto v = numbers(o.lens, "--lens");
    if (v.size() < 4 || v.size() > 9) throw Error(ErrorClass::bad_parameter, "--lens needs fx,fy,cx,cy[,k1,k2,p1,p2,k3]");
    ca::LensCalibration l;
    double* f[9] = {&l.fx, &l.fy, &l.cx, &l.cy, &l.k1, &l.k2, &l.p1, &l.p2, &l.k3};
    for (std::size_t i = 0; i < v.size(); ++i) *f[i] = v[i];
    lo.lens = l;
  }
  const ca::ChartLocation loc = ca::locate_chart(view, type, lo);

  std::string notes;
  for (const auto& n : loc.notes) notes += (notes.empty() ? "" : "; ") + n;
  Table chart{"chart", {
                           "chart",
                           "confidence",
                           "rotation_deg",
                           "from_corners",
                           "patches_detected",
                           "reprojection_rms_px",
                           "orientation_margin",
                           "check",
                           "check_passed",
                           "check_worst_pct",
                           "check_worst_patch",
                           "gradient_x_pct",
                           "gradient_y_pct",
                           "check_detail",
                           "notes",
                       },
              {}};
  chart.rows.push_back({std::string(ca::to_string(type)), loc.confidence, double(loc.rotation_deg), loc.from_corners ? "yes" : "no",
                        double(loc.patches_detected), loc.reprojection_rms_px, loc.orientation_margin, loc.check.method,
                        loc.check.passed ? "yes" : "no", loc.check.worst_disagreement * 100, loc.check.worst_patch,
                        loc.check.gradient_x * 100, loc.check.gradient_y * 100, loc.check.detail, notes});
  Table corners{"corners", {"corner", "x", "y"}, {}};
  const char* names[4] = {"top_left", "top_right", "bottom_right", "bottom_left"};
  for (std::size_t i = 0; i < 4; ++i) corners.rows.push_back({names[i], loc.corners[i].x, loc.corners[i].y});
  const bool rgb = !loc.patches.empty() && loc.patches.front().channels == 3;
  Table patches{"patches", {"id", "x", "y", "detected", "region_x", "region_y", "region_width", "region_height"}, {}};
  for (const char* c : rgb ? std::vector<const char*>{"R", "G", "B"} : std::vector<const char*>{"value"}) patches.columns.push_back(c);
  patches.columns.push_back("used");
  patches.columns.push_back("total");
  for (const auto& p : loc.patches) {
    std::vector<Cell> r{p.id, p.centre.x, p.centre.y, p.detected ? "yes" : "no", double(p.region.x), double(p.region.y),
                        double(p.region.width), double(p.region.height)};
    std::size_t used = 0, total = 0;
    for (int c = 0; c < p.channels; ++c) {
      r.emplace_back(p.value[static_cast<std::size_t>(c)].value);
      used += p.value[static_cast<std::size_t>(c)].used;
      total += p.value[static_cast<std::size_t>(c)].total;
    }
    r.emplace_back(double(used));
    r.emplace_back(double(total));
    patches.rows.push_back(std::move(r));
  }
  print_tables(std::cout, {chart, corners, patches}, o.json);
}

}  // namespace

void add_locate_chart_command(CLI::App& analyze) {
  auto o = std::make_shared<LocateCliOptions>();
  auto* c = analyze.add_subcommand("locate-chart", "Find a ColorChecker SG or 24 in a photo: corners, confidence, and every "
                                                   "patch's centre and robust value (refuses when unsure)");
  c->add_option("PHOTO", o->photo, "TIFF (8/16 bit), JPEG, PNG or PGM; a raw mosaic with --cfa (dcraw -D -4 -T)")->required();
  c->add_option("--chart", o->chart, "sg (ColorChecker SG, 140 patches) or cc24")->capture_default_str();
  c->add_option("--corners", o->corners,
                "x1,y1,x2,y2,x3,y3,x4,y4: outer corners of the patch grid, the first patch's (A1 / 1) corner first, clockwise");
  c->add_option("--cfa", o->cfa, "The photo is a raw CFA mosaic with this pattern (RGGB, BGGR, GRBG, GBRG): sampled per colour");
  c->add_option("--black", o->black, "Black level of the photo's counts (raw: e.g. 256)")->capture_default_str();
  c->add_option("--bits", o->bits, "Significant bits (12 for a 12-bit raw); sets the robust band 5·2^(bits−8)");
  c->add_option("--lens", o->lens, "Camera calibration fx,fy,cx,cy[,k1,k2,p1,p2,k3] (OpenCV model) to undo lens distortion");
  c->add_option("--fraction", o->fraction, "Sampled square side as a fraction of the patch side")->capture_default_str();
  c->add_option("--min-confidence", o->min_confidence, "Refuse below this confidence (0..1)")->capture_default_str();
  c->add_flag("--json", o->json, "JSON instead of CSV");
  c->callback([o] { run_locate(*o); });
}

}  // namespace colorlab::cli::detail
