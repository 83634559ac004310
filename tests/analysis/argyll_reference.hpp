#pragma once
// ArgyllCMS as the independent reference of the characterization tests: build a profile with colprof from one chart,
// check it with profcheck on another (or the same), as colorimetry-notes §6–7 do.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>

#include "colorlab/analysis/chart_io.hpp"
#include "test_support.hpp"

namespace colorlab::analysis::testing {

struct ArgyllResult {
  double avg = NAN, peak = NAN;
};

// algo: colprof -a (m = shaper+matrix, x = XYZ cLUT); quality: -q (l, m, h); de2000: profcheck -k.
inline ArgyllResult argyll_profile_check(const ChartData& chart, const std::string& algo, const std::filesystem::path& dir,
                                         bool de2000, const ChartData* test = nullptr, const std::string& quality = "m") {
  write_argyll_ti3(dir / "train.ti3", chart);
  const std::string base = (dir / ("p_" + algo)).string();
  std::string cmd = "cd '" + dir.string() + "' && colprof -q" + quality + " -a" + algo + " -ua -O '" + base + ".icc' train";
  if (run(cmd) != 0) return {};
  std::string check_ti3 = (dir / "train.ti3").string();
  if (test) {
    write_argyll_ti3(dir / "test.ti3", *test);
    check_ti3 = (dir / "test.ti3").string();
  }
  const std::string out = (dir / "profcheck.txt").string();
  cmd = std::string("profcheck ") + (de2000 ? "-k " : "") + "'" + check_ti3 + "' '" + base + ".icc' > '" + out + "' 2>&1";
  if (std::system(cmd.c_str()) != 0) return {};
  std::ifstream f(out);
  const std::string text((std::istreambuf_iterator<char>(f)), {});
  std::smatch m;
  ArgyllResult r;
  if (std::regex_search(text, m, std::regex(R"(max\. = ([0-9.]+), avg\. = ([0-9.]+))"))) {
    r.peak = std::stod(m[1]);
    r.avg = std::stod(m[2]);
  }
  return r;
}

}  // namespace colorlab::analysis::testing
