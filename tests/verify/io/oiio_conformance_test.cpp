// Debian's OpenImageIO 2.4 (python3-openimageio) as the independent reader and writer (issue 23): files it wrote
// read by us against the values it was given, and files we wrote read by it, each to float precision (RGBE to the
// precision of its shared 8-bit mantissa).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <regex>

#include "colorlab/verify/rendering.hpp"
#include "io_test_support.hpp"

namespace colorlab::verify {
namespace {

using test::read_bytes;
using test::read_f32;
using test::TempDir;

const std::string kScript = std::string(COLORLAB_SOURCE_DIR) + "/tests/verify/io/oiio_files.py";
// Debian's interpreter: python3-openimageio and python3-numpy are installed for it, not for a pyenv shim.
const std::string kPython = "/usr/bin/python3";

bool have_oiio() {
  return std::system((kPython + " -c 'import OpenImageIO, numpy' >/dev/null 2>&1").c_str()) == 0;
}

std::string run(const std::string& cmd, const std::filesystem::path& out) {
  const int rc = std::system((cmd + " >" + out.string() + " 2>&1").c_str());
  const std::string text = read_bytes(out);
  if (rc != 0) ADD_FAILURE() << cmd << " failed (" << rc << "):\n"
                             << text;
  return text;
}

class OiioWrittenFiles : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!have_oiio()) return;
    dir_ = new TempDir;
    run(kPython + " " + kScript + " write " + dir_->path().string(), *dir_ / "write.log");
    truth_ = nlohmann::json::parse(read_bytes(*dir_ / "truth.json"));
    std::string files;
    for (const char* f : {"rgb.hdr", "rgb_le.pfm", "rgb_be.pfm", "grey.pfm"}) files += " " + (*dir_ / f).string();
    // OpenImageIO's own decoding of the same files, the second truth for the formats with a decoding rule.
    oiio_ = nlohmann::json::parse(run(kPython + " " + kScript + " read" + files, *dir_ / "read.json"));
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    if (!dir_) GTEST_SKIP() << "needs Debian's python3-openimageio and python3-numpy (scripts/setup.sh installs them)";
  }

  // Reads NAME with our reader and checks size, channel count and every value against what OpenImageIO was given.
  static Rendering check_against_truth(const std::string& name, double rel_tolerance = 0.0) {
    const auto& t = truth_.at(name);
    Rendering r = read_rendering(*dir_ / name);
    EXPECT_EQ(r.width, t.at("width").get<int>()) << name;
    EXPECT_EQ(r.height, t.at("height").get<int>()) << name;
    EXPECT_EQ(r.channels(), static_cast<int>(t.at("channels").size())) << name;
    const std::vector<float> truth = read_f32(*dir_ / (name + ".truth.f32"));
    EXPECT_EQ(r.pixels.size(), truth.size()) << name;
    if (r.pixels.size() != truth.size()) return r;
    compare(r, truth, rel_tolerance, name + " vs the values given to OpenImageIO");
    return r;
  }

  // rel_tolerance 0: bit-exact. Otherwise relative to the pixel's largest component (RGBE shares one exponent).
  static void compare(const Rendering& r, const std::vector<float>& truth, double rel_tolerance, const std::string& what) {
    const std::size_t c = static_cast<std::size_t>(r.channels());
    int bad = 0;
    for (std::size_t p = 0; p < truth.size() / c; ++p) {
      const float mx = *std::max_element(truth.begin() + static_cast<long>(p * c), truth.begin() + static_cast<long>(p * c + c));
      for (std::size_t k = 0; k < c; ++k) {
        const float a = r.pixels[p * c + k], b = truth[p * c + k];
        const bool ok = rel_tolerance == 0.0 ? a == b : std::abs(a - b) <= rel_tolerance * mx;
        if (!ok && bad++ < 5) ADD_FAILURE() << what << ": pixel " << p << " channel " << k << ": " << a << " vs " << b;
      }
    }
    EXPECT_EQ(bad, 0) << what;
  }

  static TempDir* dir_;
  static nlohmann::json truth_;
  static nlohmann::json oiio_;
};
TempDir* OiioWrittenFiles::dir_ = nullptr;
nlohmann::json OiioWrittenFiles::truth_;
nlohmann::json OiioWrittenFiles::oiio_;

TEST_F(OiioWrittenFiles, ExrRgbWithChromaticitiesAndWhiteLuminance) {
  Rendering r = check_against_truth("rgb.exr");
  EXPECT_EQ(r.encoding, Encoding::rgb);
  EXPECT_TRUE(r.chromaticities_from_file);
  const double p3[4][2] = {{0.680, 0.320}, {0.265, 0.690}, {0.150, 0.060}, {0.3127, 0.3290}};
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 2; ++k) EXPECT_NEAR(r.chromaticities[i][k], p3[i][k], 1e-7);  // stored as float
  ASSERT_TRUE(r.white_luminance_cd_m2);
  EXPECT_DOUBLE_EQ(*r.white_luminance_cd_m2, 250.0);
}

TEST_F(OiioWrittenFiles, HalfPizRgbWithoutChromaticitiesIsRec709AndSaysSo) {
  Rendering r = check_against_truth("rgb_half.exr");
  EXPECT_FALSE(r.chromaticities_from_file);
  EXPECT_EQ(r.chromaticities, rec709_chromaticities());
  EXPECT_FALSE(r.white_luminance_cd_m2);
}

TEST_F(OiioWrittenFiles, TiledExr) { check_against_truth("rgb_tiled.exr"); }

TEST_F(OiioWrittenFiles, ExrXyz) {
  Rendering r = check_against_truth("xyz.exr");
  EXPECT_EQ(r.encoding, Encoding::xyz);
  EXPECT_EQ(r.source_format, "openexr-xyz");
}

TEST_F(OiioWrittenFiles, DataWindowInsideTheDisplayWindowIsPlacedInIt) { check_against_truth("window.exr"); }

TEST_F(OiioWrittenFiles, HandNamedSpectralBandsInEveryUnitSpelling) {
  Rendering r = check_against_truth("spectral_hand.exr");
  EXPECT_EQ(r.encoding, Encoding::spectral);
  EXPECT_FALSE(r.reflective);
  EXPECT_EQ(r.units, "W.m^-2.sr^-1");
  const auto want = truth_.at("spectral_hand.exr").at("wavelengths_nm").get<std::vector<double>>();
  ASSERT_EQ(r.wavelengths_nm.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_NEAR(r.wavelengths_nm[i], want[i], 1e-9 * want[i]);
}

// One quantisation step of the shared exponent is at most max/128 (mantissas 128..255); Radiance's decoding to
// the bin's centre is within half a step of the value written and of OpenImageIO's bin-floor decoding.
TEST_F(OiioWrittenFiles, RadianceHdrToItsMantissaPrecision) {
  Rendering r = check_against_truth("rgb.hdr", 1.0 / 128);
  compare(r, read_f32(*dir_ / "rgb.hdr.oiio.f32"), 1.0 / 128, "rgb.hdr vs OpenImageIO's reading");
}

TEST_F(OiioWrittenFiles, PfmInBothByteOrdersAndGrey) {
  for (const char* f : {"rgb_le.pfm", "rgb_be.pfm", "grey.pfm"}) {
    Rendering r = check_against_truth(f);
    std::vector<float> theirs = read_f32(*dir_ / (std::string(f) + ".oiio.f32"));
    if (std::string(f) == "grey.pfm") {  // OpenImageIO reads Pf as one channel Y
      std::vector<float> rgb;
      for (float v : theirs) rgb.insert(rgb.end(), {v, v, v});
      theirs = rgb;
    }
    compare(r, theirs, 0.0, std::string(f) + " vs OpenImageIO's reading");
  }
}

// The proposal's regular expression (Fichet, Pacanowski & Wilkie, JCGT 10(3) 2021, §3.1), written out here as
// the paper prints it, independent of the reader's copy.
const std::regex kJcgtEmissive(R"(^(S[0-3])\.(\d*,?\d*([Ee][+-]?\d+)?)(Y|Z|E|P|T|G|M|k|h|da|d|c|m|u|n|p)?(m|Hz)$)");

TEST_F(OiioWrittenFiles, OurFilesReadByOpenImageIO) {
  Rendering s;
  s.encoding = Encoding::spectral;
  s.width = 41;
  s.height = 29;
  for (int i = 0; i < 36; ++i) s.wavelengths_nm.push_back(380.0 + 10.0 * i);
  s.units = "W.m^-2.sr^-1";
  for (std::size_t i = 0; i < 36u * 41 * 29; ++i) s.pixels.push_back(static_cast<float>(std::exp(std::cos(double(i) * 0.37) * 3)));
  Rendering rgb;
  rgb.encoding = Encoding::rgb;
  rgb.width = 41;
  rgb.height = 29;
  rgb.chromaticities = {{{0.7347, 0.2653}, {0.1596, 0.8404}, {0.0366, 0.0001}, {0.3457, 0.3585}}};
  rgb.white_luminance_cd_m2 = 120.0;
  for (std::size_t i = 0; i < 3u * 41 * 29; ++i) rgb.pixels.push_back(static_cast<float>(std::sin(double(i)) * 100));
  Rendering xyz = rgb;
  xyz.encoding = Encoding::xyz;
  xyz.white_luminance_cd_m2.reset();
  for (auto& v : xyz.pixels) v = std::abs(v);
  write_openexr(s, *dir_ / "ours_spectral.exr");
  write_openexr(rgb, *dir_ / "ours_rgb.exr");
  write_openexr(xyz, *dir_ / "ours_xyz.exr", {false});
  const auto report = nlohmann::json::parse(run(kPython + " " + kScript + " read " + (*dir_ / "ours_spectral.exr").string() +
                                                    " " + (*dir_ / "ours_rgb.exr").string() + " " + (*dir_ / "ours_xyz.exr").string(),
                                                *dir_ / "ours.json"));

  // Spectral: every band channel matches the paper's expression, names each of our bands, and holds our values.
  const auto& sp = report.at((*dir_ / "ours_spectral.exr").string());
  const auto names = sp.at("channels").get<std::vector<std::string>>();
  EXPECT_EQ(sp.at("width").get<int>(), 41);
  EXPECT_EQ(sp.at("attributes").at("spectralLayoutVersion").get<std::string>(), "1.0");
  EXPECT_EQ(sp.at("attributes").at("emissiveUnits").get<std::string>(), "W.m^-2.sr^-1");
  for (const char* preview : {"R", "G", "B"}) EXPECT_NE(std::find(names.begin(), names.end(), preview), names.end()) << preview;
  const std::vector<float> theirs = read_f32(*dir_ / "ours_spectral.exr.oiio.f32");
  ASSERT_EQ(theirs.size(), names.size() * 41 * 29);
  int bands_seen = 0;
  for (std::size_t c = 0; c < names.size(); ++c) {
    if (names[c] == "R" || names[c] == "G" || names[c] == "B") continue;
    std::smatch m;
    ASSERT_TRUE(std::regex_match(names[c], m, kJcgtEmissive)) << names[c];
    EXPECT_EQ(m[1].str(), "S0");
    EXPECT_EQ(m[4].str() + m[5].str(), "nm") << names[c];
    std::string v = m[2].str();
    std::replace(v.begin(), v.end(), ',', '.');
    const auto band = static_cast<std::size_t>(std::lround((std::stod(v) - 380.0) / 10.0));
    ASSERT_LT(band, 36u) << names[c];
    EXPECT_DOUBLE_EQ(std::stod(v), s.wavelengths_nm[band]) << names[c];
    ++bands_seen;
    int bad = 0;
    for (std::size_t p = 0; p < 41u * 29; ++p)
      if (theirs[p * names.size() + c] != s.pixels[p * 36 + band] && bad++ < 3)
        ADD_FAILURE() << names[c] << " pixel " << p << ": " << theirs[p * names.size() + c] << " vs " << s.pixels[p * 36 + band];
  }
  EXPECT_EQ(bands_seen, 36);

  for (const auto* im : {&rgb, &xyz}) {
    const std::string file = (*dir_ / (im == &rgb ? "ours_rgb.exr" : "ours_xyz.exr")).string();
    const auto& rep = report.at(file);
    const auto ch = rep.at("channels").get<std::vector<std::string>>();
    EXPECT_EQ(ch, im == &rgb ? (std::vector<std::string>{"R", "G", "B"}) : (std::vector<std::string>{"X", "Y", "Z"}));
    const std::vector<float> v = read_f32(file + ".oiio.f32");
    EXPECT_EQ(v, im->pixels) << file;
  }
  const auto& attrs = report.at((*dir_ / "ours_rgb.exr").string()).at("attributes");
  const auto chroma = attrs.at("chromaticities").get<std::vector<double>>();
  ASSERT_EQ(chroma.size(), 8u);
  for (int i = 0; i < 8; ++i) EXPECT_NEAR(chroma[i], rgb.chromaticities[i / 2][i % 2], 1e-7);
  EXPECT_DOUBLE_EQ(attrs.at("whiteLuminance").get<double>(), 120.0);
}

}  // namespace
}  // namespace colorlab::verify
