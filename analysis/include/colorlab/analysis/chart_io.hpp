#pragma once
// Chart data files: patch numbering, camera/reference tables in CSV or CGATS, and Argyll .ti3 output.
#include <filesystem>
#include <optional>
#include <string>

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

// CTI3 file that ArgyllCMS colprof reads: RGB (0–1 in, written 0–100) with XYZ, and spectra when given
// (written in percent).
void write_argyll_ti3(const std::filesystem::path& path, const ChartData& chart,
                      const SpectralSet* reflectances = nullptr);

// A CGATS spectral file (.sp for one spectrum, .cmf / .ti1-like with SAMPLE_ID for several) for spec2cie & co.
void write_spectra_cgats(const std::filesystem::path& path, const SpectralSet& spectra, const std::string& file_type = "CTI1");

}  // namespace colorlab::analysis
