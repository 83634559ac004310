// The readers on files whose every byte the test states (Radiance RGBE orientations, run-length schemes,
// EXPOSURE, PFM byte orders), the conversions to XYZ against published constants, and our own round trip.
#include <gtest/gtest.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>

#include <cmath>

#include "colorlab/verify/rendering.hpp"
#include "colorlab/verify/rendering_xyz.hpp"
#include "io_test_support.hpp"

namespace colorlab::verify {
namespace {

using test::read_bytes;
using test::TempDir;
using test::thrown;
using test::write_bytes;

std::string rgbe_header(const std::string& extra, const std::string& resolution) {
  return "#?RADIANCE\n# written by the test\nFORMAT=32-bit_rle_rgbe\n" + extra + (extra.empty() ? "" : "\n") + "\n" +
         resolution + "\n";
}

// Pixel k of a 3 x 2 image as RGBE: mantissas 100+k, 50+k, 10+k with exponent 136, i.e. the value m + 0.5.
std::string pixel(int k) {
  return {static_cast<char>(100 + k), static_cast<char>(50 + k), static_cast<char>(10 + k), static_cast<char>(136)};
}

TEST(VerifyIoRgbe, DecodesToTheCentreOfTheMantissaBinAndDividesOutExposure) {
  TempDir dir;
  // (128, 64, 32) at exponent 129: Radiance's colr_color gives (m + 0.5) · 2^(129−136).
  write_bytes(dir / "a.hdr", rgbe_header("EXPOSURE=2\nEXPOSURE=0.5\nEXPOSURE=4", "-Y 1 +X 1") +
                                 std::string{char(128), char(64), char(32), char(129)});
  Rendering r = read_rendering(dir / "a.hdr");
  EXPECT_EQ(r.encoding, Encoding::rgb);
  EXPECT_EQ(r.source_format, "rgbe");
  EXPECT_FALSE(r.chromaticities_from_file);
  EXPECT_DOUBLE_EQ(r.chromaticities[1][0], 0.290);  // Radiance's standard green, not Rec. 709's
  EXPECT_DOUBLE_EQ(r.chromaticities[3][0], 1.0 / 3.0);
  EXPECT_FLOAT_EQ(r.pixels[0], 128.5f / 128 / 4);
  EXPECT_FLOAT_EQ(r.pixels[1], 64.5f / 128 / 4);
  EXPECT_FLOAT_EQ(r.pixels[2], 32.5f / 128 / 4);
}

TEST(VerifyIoRgbe, ZeroExponentIsBlackAndPrimariesComeFromTheHeader) {
  TempDir dir;
  write_bytes(dir / "b.hdr", rgbe_header("PRIMARIES= 0.7347 0.2653 0.1596 0.8404 0.0366 0.0001 0.3457 0.3585", "-Y 1 +X 1") +
                                 std::string{char(200), char(200), char(200), char(0)});
  Rendering r = read_rendering(dir / "b.hdr");
  EXPECT_TRUE(r.chromaticities_from_file);
  EXPECT_DOUBLE_EQ(r.chromaticities[0][0], 0.7347);
  EXPECT_DOUBLE_EQ(r.chromaticities[3][1], 0.3585);
  EXPECT_EQ(r.pixels, (std::vector<float>{0, 0, 0}));
}

// Radiance's resolution string (resolu.c): the first axis is the scanline order; −Y starts at the top, +X at the left.
TEST(VerifyIoRgbe, EveryOrientationPutsPixelsWhereTheResolutionStringSays) {
  TempDir dir;
  struct Case {
    const char* resolution;
    std::vector<int> stored;  // image index (y·3 + x, top row 0 1 2) of each stored pixel in file order
  } cases[] = {{"-Y 2 +X 3", {0, 1, 2, 3, 4, 5}}, {"+Y 2 +X 3", {3, 4, 5, 0, 1, 2}}, {"-Y 2 -X 3", {2, 1, 0, 5, 4, 3}}, {"+X 3 -Y 2", {0, 3, 1, 4, 2, 5}}, {"-X 3 +Y 2", {5, 2, 4, 1, 3, 0}}};
  for (const auto& c : cases) {
    std::string body;
    for (int k : c.stored) body += pixel(k);
    write_bytes(dir / "o.hdr", rgbe_header("", c.resolution) + body);
    Rendering r = read_rendering(dir / "o.hdr");
    ASSERT_EQ(r.width, 3) << c.resolution;
    ASSERT_EQ(r.height, 2) << c.resolution;
    for (int k = 0; k < 6; ++k) EXPECT_FLOAT_EQ(r.pixel(k % 3, k / 3)[0], 100.5f + static_cast<float>(k)) << c.resolution << " pixel " << k;
  }
}

TEST(VerifyIoRgbe, NewStyleRunLengthScanlines) {
  TempDir dir;
  // Width 10: R one run of 10 × 7; G ten literals 0..9; B a run of 5 × 3 then 5 literals 20..24; E a run of 10 × 136.
  std::string line{2, 2, 0, 10};
  line += std::string{char(128 + 10), char(7)};
  line += char(10);
  for (int i = 0; i < 10; ++i) line += char(i);
  line += std::string{char(128 + 5), char(3), char(5), char(20), char(21), char(22), char(23), char(24)};
  line += std::string{char(128 + 10), char(136)};
  write_bytes(dir / "rle.hdr", rgbe_header("", "-Y 2 +X 10") + line + line);
  Rendering r = read_rendering(dir / "rle.hdr");
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 10; ++x) {
      EXPECT_FLOAT_EQ(r.pixel(x, y)[0], 7.5f);
      EXPECT_FLOAT_EQ(r.pixel(x, y)[1], static_cast<float>(x) + 0.5f);
      EXPECT_FLOAT_EQ(r.pixel(x, y)[2], x < 5 ? 3.5f : static_cast<float>(15 + x) + 0.5f);
    }
}

TEST(VerifyIoRgbe, OldStyleRepeatCodesAndXyze) {
  TempDir dir;
  std::string body = pixel(0) + std::string{1, 1, 1, 3};  // pixel 0, then it again 3 times
  write_bytes(dir / "old.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 4\n" + body);
  Rendering r = read_rendering(dir / "old.hdr");
  EXPECT_EQ(r.encoding, Encoding::xyz);
  for (int x = 0; x < 4; ++x) EXPECT_FLOAT_EQ(r.pixel(x, 0)[1], 50.5f);
}

TEST(VerifyIoPfm, BottomUpRowsInBothByteOrders) {
  TempDir dir;
  // 2 x 2 grey: stored bottom row first: 1, 2 then top row 3, 4.
  const float v[4] = {1, 2, 3, 4};
  std::string le, be;
  for (float f : v) {
    char b[4];
    std::memcpy(b, &f, 4);
    le.append(b, 4);
    be += std::string{b[3], b[2], b[1], b[0]};
  }
  write_bytes(dir / "le.pfm", "Pf\n2 2\n-1.000000\n" + le);
  write_bytes(dir / "be.pfm", "Pf\n2 2\n1.0\n" + be);
  for (const char* f : {"le.pfm", "be.pfm"}) {
    Rendering r = read_rendering(dir / f);
    EXPECT_EQ(r.encoding, Encoding::rgb);
    EXPECT_EQ(r.source_format, "pfm");
    EXPECT_FLOAT_EQ(r.pixel(0, 0)[2], 3.0f) << f;
    EXPECT_FLOAT_EQ(r.pixel(1, 0)[0], 4.0f) << f;
    EXPECT_FLOAT_EQ(r.pixel(0, 1)[1], 1.0f) << f;
    EXPECT_FLOAT_EQ(r.pixel(1, 1)[0], 2.0f) << f;
  }
}

TEST(VerifyIoSpectralChannels, NamesFollowTheJcgtLayoutAndParseBack) {
  EXPECT_EQ(spectral_channel_name(550.0), "S0.550,000000nm");
  EXPECT_EQ(spectral_channel_name(412.5, true), "T.412,500000nm");
  EXPECT_DOUBLE_EQ(*spectral_channel_wavelength_nm("S0.550,000000nm"), 550.0);
  EXPECT_NEAR(*spectral_channel_wavelength_nm("S0.0,55um"), 550.0, 1e-9);
  EXPECT_NEAR(*spectral_channel_wavelength_nm("S0.5,5E-7m"), 550.0, 1e-9);
  EXPECT_NEAR(*spectral_channel_wavelength_nm("S0.545,077196THz"), 299792458.0 / 545.077196e12 * 1e9, 1e-9);
  EXPECT_NEAR(*spectral_channel_wavelength_nm("T.700nm", "T"), 700.0, 1e-12);
  EXPECT_FALSE(spectral_channel_wavelength_nm("S0.550.0nm"));  // a dot is not the decimal separator
  EXPECT_FALSE(spectral_channel_wavelength_nm("S1.550nm"));    // another Stokes component
  EXPECT_FALSE(spectral_channel_wavelength_nm("S0.550nm", "T"));
  EXPECT_FALSE(spectral_channel_wavelength_nm("S0.550"));
  EXPECT_FALSE(spectral_channel_wavelength_nm("S0.,nm"));
}

TEST(VerifyIoSpectralChannels, BoxesMeetHalfwayBetweenCentres) {
  EXPECT_EQ(band_edges_nm({400, 410, 430}), (std::vector<double>{395, 405, 420, 440}));
  EXPECT_EQ(thrown([] { band_edges_nm({400}); }).cls, ErrorClass::bad_data);
  EXPECT_EQ(thrown([] { band_edges_nm({400, 400}); }).cls, ErrorClass::bad_data);
}

// IEC 61966-2-1 (sRGB), §5.2: the RGB → XYZ matrix to the four decimals the standard prints.
TEST(VerifyIoToXyz, Rec709MatrixIsTheSrgbStandardsMatrix) {
  const double iec[3][3] = {{0.4124, 0.3576, 0.1805}, {0.2126, 0.7152, 0.0722}, {0.0193, 0.1192, 0.9505}};
  const Matrix3 m = rgb_to_xyz_matrix(rec709_chromaticities());
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(m[r][c], iec[r][c], 1.5e-4) << r << "," << c;
  // OpenEXR's XYZ convention (primaries at the corners, white E) is the identity.
  const Matrix3 id = rgb_to_xyz_matrix({{{1, 0}, {0, 1}, {0, 0}, {1.0 / 3, 1.0 / 3}}});
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(id[r][c], r == c ? 1.0 : 0.0, 1e-12);
  EXPECT_EQ(thrown([] { rgb_to_xyz_matrix({{{0.2, 0.2}, {0.4, 0.4}, {0.6, 0.6}, {0.3, 0.3}}}); }).cls, ErrorClass::bad_data);
}

TEST(VerifyIoToXyz, RgbWhiteHasYOneOrTheFilesWhiteLuminance) {
  Rendering r;
  r.encoding = Encoding::rgb;
  r.width = r.height = 1;
  r.chromaticities = rec709_chromaticities();
  r.pixels = {1, 1, 1};
  Rendering x = to_xyz(r);
  EXPECT_NEAR(x.pixels[1], 1.0, 1e-6);
  EXPECT_NEAR(x.pixels[0] / x.pixels[1], 0.3127 / 0.3290, 1e-5);  // D65's X/Y
  EXPECT_EQ(x.units, "");
  r.white_luminance_cd_m2 = 120.0;
  x = to_xyz(r);
  EXPECT_NEAR(x.pixels[1], 120.0, 1e-4);
  EXPECT_EQ(x.units, "cd/m^2");
}

Rendering flat_spectrum(double from, double to, double step, float radiance) {
  Rendering r;
  r.encoding = Encoding::spectral;
  r.width = 2;
  r.height = 1;
  for (int i = 0; from + i * step <= to + 1e-9; ++i) r.wavelengths_nm.push_back(from + i * step);
  r.pixels.assign(r.wavelengths_nm.size() * 2, radiance);
  return r;
}

// CIE 15:2004: ∫ȳ(λ) dλ of the 1931 observer over 360–830 nm is 106.857 nm, and the equal-energy spectrum sits at
// x = y = 1/3, so a flat radiance of 1 W·m⁻²·sr⁻¹·nm⁻¹ is 683 × 106.857 cd/m² with X = Y = Z.
TEST(VerifyIoToXyz, FlatSpectralRadianceGivesTheObserversIntegral) {
  Rendering x = to_xyz(flat_spectrum(360, 830, 10, 1.0f));
  EXPECT_EQ(x.units, "cd/m^2");
  EXPECT_NEAR(x.pixels[1], 683.0 * 106.857, 683.0 * 106.857 * 1e-3);
  EXPECT_NEAR(x.pixels[0] / x.pixels[1], 1.0, 2e-3);
  EXPECT_NEAR(x.pixels[2] / x.pixels[1], 1.0, 2e-3);
  EXPECT_EQ(x.pixels[3], x.pixels[0]);
}

// ȳ(555 nm) = 1.0000 (CIE 1931 table): a 1 nm band there carries 683 cd/m² per unit spectral radiance.
TEST(VerifyIoToXyz, ANarrowBandAt555nmIs683CandelaPerUnitRadiance) {
  Rendering r = flat_spectrum(554, 556, 1, 0.0f);
  r.pixels[1] = 1.0f;
  const Rendering x = to_xyz(r);
  EXPECT_NEAR(x.pixels[1], 683.0, 683.0 * 1e-3);
  r.reflective = true;
  EXPECT_EQ(thrown([&] { to_xyz(r); }).cls, ErrorClass::unsupported);
}

TEST(VerifyIoRoundTrip, SpectralXyzAndRgbComeBackBitExact) {
  TempDir dir;
  Rendering s = flat_spectrum(380, 730, 10, 0.0f);  // 36 bands
  s.width = 7;
  s.height = 5;
  s.units = "W.m^-2.sr^-1";
  s.pixels.resize(36 * 35);
  for (std::size_t i = 0; i < s.pixels.size(); ++i) s.pixels[i] = static_cast<float>(std::exp(std::sin(double(i)) * 4.0));
  for (bool compress : {true, false}) {
    write_openexr(s, dir / "s.exr", {compress});
    Rendering back = read_rendering(dir / "s.exr");
    EXPECT_EQ(back.encoding, Encoding::spectral);
    EXPECT_EQ(back.source_format, "openexr-spectral");
    EXPECT_EQ(back.units, "W.m^-2.sr^-1");
    ASSERT_EQ(back.wavelengths_nm.size(), s.wavelengths_nm.size());
    for (std::size_t i = 0; i < s.wavelengths_nm.size(); ++i) EXPECT_NEAR(back.wavelengths_nm[i], s.wavelengths_nm[i], 1e-6);
    EXPECT_EQ(back.pixels, s.pixels);
  }
  s.reflective = true;
  s.units.clear();
  write_openexr(s, dir / "t.exr");
  Rendering t = read_rendering(dir / "t.exr");
  EXPECT_TRUE(t.reflective);
  EXPECT_EQ(t.pixels, s.pixels);

  Rendering rgb;
  rgb.encoding = Encoding::rgb;
  rgb.width = 3;
  rgb.height = 2;
  rgb.chromaticities = {{{0.7347, 0.2653}, {0.1596, 0.8404}, {0.0366, 0.0001}, {0.3457, 0.3585}}};
  rgb.white_luminance_cd_m2 = 80.0;
  rgb.pixels = {0.5f, -0.25f, 3, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};
  write_openexr(rgb, dir / "rgb.exr");
  Rendering rb = read_rendering(dir / "rgb.exr");
  EXPECT_EQ(rb.encoding, Encoding::rgb);
  EXPECT_TRUE(rb.chromaticities_from_file);
  EXPECT_NEAR(rb.chromaticities[2][1], 0.0001, 1e-7);
  EXPECT_DOUBLE_EQ(*rb.white_luminance_cd_m2, 80.0);
  EXPECT_EQ(rb.pixels, rgb.pixels);  // a negative (out-of-gamut) RGB value is legal

  rgb.encoding = Encoding::xyz;
  rgb.pixels[1] = 0.25f;
  rgb.white_luminance_cd_m2.reset();
  write_openexr(rgb, dir / "xyz.exr");
  Rendering xb = read_rendering(dir / "xyz.exr");
  EXPECT_EQ(xb.encoding, Encoding::xyz);
  EXPECT_EQ(xb.pixels, rgb.pixels);
}

// A multi-part file with an RGB preview part first and the spectral part second: the spectral part is the rendering.
TEST(VerifyIoRoundTrip, MultiPartFileYieldsItsSpectralPart) {
  TempDir dir;
  const int w = 5, h = 3;
  std::vector<Imf::Header> headers(2, Imf::Header(w, h));
  const std::vector<std::vector<std::string>> names = {{"R", "G", "B"}, {"S0.450nm", "S0.550nm", "S0.650nm", "S0.750nm"}};
  for (int p = 0; p < 2; ++p) {
    headers[p].setName(p == 0 ? "preview" : "spectral");
    headers[p].setType(Imf::SCANLINEIMAGE);
    for (const auto& n : names[p]) headers[p].channels().insert(n, Imf::Channel(Imf::FLOAT));
  }
  std::vector<std::vector<float>> data(2);
  {
    Imf::MultiPartOutputFile out((dir / "multi.exr").c_str(), headers.data(), 2);
    for (int p = 0; p < 2; ++p) {
      const std::size_t c = names[p].size();
      for (std::size_t i = 0; i < c * w * h; ++i) data[p].push_back(static_cast<float>(p * 1000 + i));
      Imf::FrameBuffer fb;
      for (std::size_t k = 0; k < c; ++k)
        fb.insert(names[p][k], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(data[p].data() + k), 4 * c, 4 * c * w));
      Imf::OutputPart part(out, p);
      part.setFrameBuffer(fb);
      part.writePixels(h);
    }
  }
  Rendering r = read_rendering(dir / "multi.exr");
  EXPECT_EQ(r.encoding, Encoding::spectral);
  EXPECT_EQ(r.wavelengths_nm, (std::vector<double>{450, 550, 650, 750}));
  EXPECT_EQ(r.pixels, data[1]);
}

TEST(VerifyIoAssemble, OneBandPerRenderFromGreyRgbImages) {
  std::vector<Rendering> bands(3);
  for (int b = 0; b < 3; ++b) {
    bands[b].encoding = Encoding::rgb;
    bands[b].width = 2;
    bands[b].height = 2;
    for (int p = 0; p < 4; ++p)
      for (int c = 0; c < 3; ++c) bands[b].pixels.push_back(static_cast<float>(10 * b + p));
  }
  Rendering s = assemble_spectral(bands, {450, 550, 650});
  EXPECT_EQ(s.encoding, Encoding::spectral);
  EXPECT_EQ(s.channels(), 3);
  EXPECT_EQ(s.units, "W.m^-2.sr^-1");
  EXPECT_FLOAT_EQ(s.pixel(1, 1)[2], 23.0f);
  EXPECT_FLOAT_EQ(s.pixel(1, 0)[1], 11.0f);
  bands[2].width = 4;
  bands[2].height = 1;
  EXPECT_EQ(thrown([&] { assemble_spectral(bands, {450, 550, 650}); }).cls, ErrorClass::bad_data);
  EXPECT_EQ(thrown([&] { assemble_spectral(bands, {450, 550}); }).cls, ErrorClass::bad_parameter);
  EXPECT_EQ(thrown([&] { assemble_spectral(bands, {450, 450, 650}); }).cls, ErrorClass::bad_parameter);
}

}  // namespace
}  // namespace colorlab::verify
