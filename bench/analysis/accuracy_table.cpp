// docs/ACCURACY.md's table: colorlab's cross-validated model selection against ArgyllCMS colprof -ax (XYZ cLUT) and
// -am (shaper + matrix), both trained on the same synthetic ColorChecker SG and checked by profcheck on the same
// synthetic CC24, for several cameras (camspec curves) and for a lamp change between training and test.
//
//   bench_analysis_accuracy [--quality m] [--cameras Canon_20D,Nikon_D3X] [--conditions D50:D50,D65:A] [--keep DIR]
//                           [--oracle 1]
//
// Prints one Markdown row per camera and condition, then a tally. --oracle 1 adds, per row, the candidate with the
// lowest maximum on the TEST chart (not a selection anyone could make; it shows whether any family could have won). Needs ../shared/data and Argyll on PATH.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "colorlab/analysis/characterization.hpp"
#include "colorlab/analysis/chart_io.hpp"
#include "colorlab/analysis/csv.hpp"
#include "colorlab/analysis/standard_data.hpp"
#include "colorlab/core/data_paths.hpp"
#include "synthetic_chart.hpp"

namespace ca = colorlab::analysis;
namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kCameras = {"Canon_20D", "Canon_5DMarkII", "Nikon_D3X", "SONY_NEX_5N",
                                           "Olympus_E_PL2", "Pentax_K_5", "Phase_One", "Nokia_N900",
                                           "Point_Grey_Grasshopper_50S5C"};
const std::vector<std::pair<std::string, std::string>> kConditions = {{"D50", "D50"}, {"D65", "D65"}, {"D65", "A"}, {"D65", "F11"}};

struct Figure {
  double mean = NAN, max = NAN;
};

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, sep);)
    if (!item.empty()) out.push_back(item);
  return out;
}

// colprof builds the profile once per training chart; profcheck -k reports CIEDE2000 on a test chart.
bool colprof(const fs::path& dir, const std::string& algo, const std::string& quality) {
  const std::string cmd = "cd '" + dir.string() + "' && colprof -q" + quality + " -a" + algo + " -ua -O p_" + algo + ".icc train >colprof_" +
                          algo + ".log 2>&1";
  return std::system(cmd.c_str()) == 0;
}

Figure profcheck(const fs::path& dir, const std::string& algo) {
  const fs::path out = dir / ("profcheck_" + algo + ".txt");
  const std::string cmd = "profcheck -k '" + (dir / "test.ti3").string() + "' '" + (dir / ("p_" + algo + ".icc")).string() + "' > '" +
                          out.string() + "' 2>&1";
  if (std::system(cmd.c_str()) != 0) return {};
  std::ifstream f(out);
  const std::string text((std::istreambuf_iterator<char>(f)), {});
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(R"(max\. = ([0-9.]+), avg\. = ([0-9.]+))"))) return {};
  return {std::stod(m[2]), std::stod(m[1])};
}

std::string fmt(const Figure& f) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(2) << f.mean << " / " << f.max;
  return s.str();
}

const std::vector<ca::FitTarget> kTargets = {ca::FitTarget::xyz_then_lab, ca::FitTarget::xyz_lightness_weighted, ca::FitTarget::lab_direct};

struct Chosen {
  std::string label;
  std::optional<ca::Characterization> model;
};

Chosen select(const std::vector<std::string>& methods, const ca::ChartData& train) {
  ca::FitOptions o;
  o.input_scale = 1.0;
  const auto sel = ca::select_method(methods, kTargets, train, o, ca::CvSpec::loo());
  const auto& c = sel.candidates[sel.chosen];
  o.target = c.target;
  std::ostringstream label;
  label << c.method << " " << ca::to_string(c.target) << " (" << std::fixed << std::setprecision(0) << c.parameters << ")";
  return {label.str(), ca::fit_method(c.method, train, o)};
}

}  // namespace

int main(int argc, char** argv) {
  std::string quality = "m";
  std::vector<std::string> cameras = kCameras;
  auto conditions = kConditions;
  std::optional<fs::path> keep;
  bool oracle = false;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--quality") quality = v;
    else if (a == "--cameras") cameras = ca::parse_csv_row(v, "--cameras");
    else if (a == "--keep") keep = v;
    else if (a == "--oracle") oracle = v == "1";
    else if (a == "--conditions") {
      conditions.clear();
      for (const auto& c : ca::parse_csv_row(v, "--conditions")) {
        const auto p = split(c, ':');
        if (p.size() == 2) conditions.emplace_back(p[0], p[1]);
      }
    } else {
      std::cerr << "unknown option " << a << "\n";
      return 2;
    }
  }
  const auto sg_file = colorlab::paths::shared_data_file("colorcheckersg_isetcam_imai_lin_2010_10nm_380_730.csv");
  const auto cc_file = colorlab::paths::shared_data_file("colorchecker24_babelcolor_avg30_10nm_380_730.csv");
  const auto cam_file = colorlab::paths::shared_data_file("camera_ssf_camspec_jiang2013_28cams_10nm_400_720.csv");
  if (!sg_file || !cc_file || !cam_file) {
    std::cerr << "needs ../shared/data (SG, CC24 and camspec files)\n";
    return 1;
  }
  if (std::system("command -v colprof >/dev/null && command -v profcheck >/dev/null") != 0) {
    std::cerr << "needs ArgyllCMS colprof and profcheck on PATH (Debian package argyll)\n";
    return 1;
  }
  const ca::SpectralSet sg = ca::read_spectra(*sg_file), cc = ca::read_spectra(*cc_file), cams = ca::read_spectra(*cam_file);
  std::vector<std::string> polys;
  for (const auto& s : ca::all_term_sets()) polys.push_back(s.name);
  const fs::path root = keep ? *keep : fs::temp_directory_path() / ("colorlab-accuracy-" + std::to_string(::getpid()));

  std::cout << "| camera | lamp train → test | colorlab chosen (effective parameters) | colorlab mean / max ΔE00 | colprof -q" << quality
            << " -ax | colprof -q" << quality << " -am | best polynomial (chosen among polynomials) |\n|---|---|---|---|---|---|---|\n";
  int rows = 0, beat_ax_mean = 0, beat_ax_max = 0, beat_am_mean = 0, beat_am_max = 0;
  for (const auto& cam : cameras) {
    const ca::SpectralSet curves = colorlab::bench::camera_curves(cams, cam);
    std::map<std::string, std::pair<Chosen, Chosen>> trained;  // per training lamp: all families, polynomials only
    std::map<std::string, ca::ChartData> train_charts;
    for (const auto& [train_lamp, test_lamp] : conditions) {
      const fs::path dir = root / cam / train_lamp;
      if (!trained.count(train_lamp)) {
        fs::create_directories(dir);
        const ca::ChartData train = colorlab::bench::render_chart(sg, ca::load_illuminant(train_lamp), curves);
        ca::write_argyll_ti3(dir / "train.ti3", train);
        if (!colprof(dir, "x", quality) || !colprof(dir, "m", quality)) {
          std::cerr << "colprof failed in " << dir << "\n";
          return 1;
        }
        trained.emplace(train_lamp, std::make_pair(select(ca::all_methods(), train), select(polys, train)));
        train_charts.emplace(train_lamp, train);
      }
      const auto& [all, poly] = trained.at(train_lamp);
      const ca::ChartData test = colorlab::bench::render_chart(cc, ca::load_illuminant(test_lamp), curves);
      ca::write_argyll_ti3(dir / "test.ti3", test);
      const Figure ax = profcheck(dir, "x"), am = profcheck(dir, "m");
      const auto e = ca::evaluate(all.model->apply(test.rgb), test.lab);
      const auto pe = ca::evaluate(poly.model->apply(test.rgb), test.lab);
      const Figure ours{e.s00.mean, e.s00.max}, best_poly{pe.s00.mean, pe.s00.max};
      ++rows;
      beat_ax_mean += ours.mean < ax.mean;
      beat_ax_max += ours.max < ax.max;
      beat_am_mean += ours.mean < am.mean;
      beat_am_max += ours.max < am.max;
      std::cout << "| " << cam << " | " << train_lamp << " → " << test_lamp << " | " << all.label << " | **" << fmt(ours) << "** | "
                << fmt(ax) << " | " << fmt(am) << " | " << poly.label << ": " << fmt(best_poly) << " |";
      if (oracle) {
        Figure best{INFINITY, INFINITY};
        std::string which;
        for (const auto t : kTargets)
          for (const auto& m : ca::all_methods()) {
            ca::FitOptions o;
            o.input_scale = 1.0;
            o.target = t;
            try {
              const auto pe2 = ca::evaluate(ca::fit_method(m, train_charts.at(train_lamp), o).apply(test.rgb), test.lab);
              if (pe2.s00.max < best.max) {
                best = {pe2.s00.mean, pe2.s00.max};
                which = m + " " + ca::to_string(t);
              }
            } catch (const std::exception&) {
              // rank-deficient candidate: not a contender
            }
          }
        std::cout << " oracle (lowest test maximum of all candidates): " << which << " " << fmt(best) << " |";
      }
      std::cout << std::endl;
    }
  }
  std::cout << "\ncolorlab below colprof -ax: mean in " << beat_ax_mean << "/" << rows << ", max in " << beat_ax_max << "/" << rows
            << "; below colprof -am: mean in " << beat_am_mean << "/" << rows << ", max in " << beat_am_max << "/" << rows << "\n";
  if (!keep) {
    std::error_code ec;
    fs::remove_all(root, ec);
  }
  return 0;
}
