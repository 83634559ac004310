#pragma once
// Chart data files: patch numbering, camera/reference tables in CSV or CGATS, and Argyll .ti3 output.
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "colorlab/analysis/cgats.hpp"

#include "colorlab/analysis/regression.hpp"
#include "colorlab/analysis/spectral.hpp"

namespace colorlab::analysis {

// The dissertation numbers SG patches 1–140 left to right from the upper left; files name them A1…N10
// (letter = column A–N, number = row 1–10). The one place this mapping lives.
std::string sg_patch_id(int number);
int sg_patch_number(const std::string& id);

// CSV (columns id/patch_id, R,G,B and X,Y,Z and/or L,a,b, optionally suffixed _D50) or CGATS (.ti3: SAMPLE_ID,
// RGB_R.., XYZ_X.., LAB_L..). A missing XYZ or L*a*b* is computed from the other with `white`.
// RGB_* in a .ti3 are on 0–100 and returned as 0–1.
ChartData read_chart(const std::filesystem::path& path, const Xyz& white = kIccD50White);

// What an Argyll .ti3 says about its data beyond the patches (ArgyllCMS's ti3 format description).
struct Ti3Options {
  std::string descriptor = "colorlab chart data";
  // INPUT: a camera or scanner's values of a reflective chart (colprof makes an input profile);
  // OUTPUT: device values a chart was made from, read patch by patch (chartread's kind).
  std::string device_class = "INPUT";
  bool with_lab = false;                                      // LAB_L/A/B beside XYZ_X/Y/Z
  std::vector<std::pair<std::string, std::string>> keywords;  // more, e.g. where the data came from
};

// CTI3 table that ArgyllCMS colprof, profcheck and spec2cie read: RGB (0–1 in, written 0–100) with XYZ
// (Y = 100 for the perfect reflector), and reflectance spectra (0–1 in, written in percent) when given.
CgatsTable argyll_ti3_table(const ChartData& chart, const SpectralSet* reflectances = nullptr, const Ti3Options& options = {});
std::string format_argyll_ti3(const ChartData& chart, const SpectralSet* reflectances = nullptr, const Ti3Options& options = {});
void write_argyll_ti3(const std::filesystem::path& path, const ChartData& chart,
                      const SpectralSet* reflectances = nullptr);

// A CGATS spectral file (.sp for one spectrum, .cmf / .ti1-like with SAMPLE_ID for several) for spec2cie & co.
void write_spectra_cgats(const std::filesystem::path& path, const SpectralSet& spectra, const std::string& file_type = "CTI1");

}  // namespace colorlab::analysis
