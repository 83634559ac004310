// Every class of malformed rendering gives a typed colorlab::Error saying what and where, never a crash or a
// silently wrong image: truncation, missing channels, inconsistent sizes, values light cannot have, unknown kinds.
#include <gtest/gtest.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include <cmath>
#include <limits>

#include "colorlab/verify/rendering.hpp"
#include "io_test_support.hpp"

namespace colorlab::verify {
namespace {

using test::read_bytes;
using test::TempDir;
using test::thrown;
using test::write_bytes;

// An OpenEXR file with exactly these channels (written by OpenEXR itself, not by the code under test).
void write_exr(const std::filesystem::path& p, const std::vector<std::string>& names, int w, int h,
               float (*value)(int x, int y, int c) = nullptr, Imath::Box2i data_window = {}) {
  Imf::Header header(w, h);
  if (!data_window.isEmpty()) header.dataWindow() = data_window;
  const Imath::Box2i dw = header.dataWindow();
  const int dwid = dw.max.x - dw.min.x + 1, dhei = dw.max.y - dw.min.y + 1;
  std::vector<float> buf(static_cast<std::size_t>(dwid) * dhei * names.size());
  for (int y = 0; y < dhei; ++y)
    for (int x = 0; x < dwid; ++x)
      for (std::size_t c = 0; c < names.size(); ++c)
        buf[(static_cast<std::size_t>(y) * dwid + x) * names.size() + c] = value ? value(x, y, static_cast<int>(c)) : 0.25f;
  Imf::FrameBuffer fb;
  const std::size_t xs = 4 * names.size(), ys = xs * static_cast<std::size_t>(dwid);
  char* base = reinterpret_cast<char*>(buf.data()) - dw.min.x * static_cast<std::ptrdiff_t>(xs) - dw.min.y * static_cast<std::ptrdiff_t>(ys);
  for (std::size_t c = 0; c < names.size(); ++c) {
    header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + 4 * c, xs, ys));
  }
  Imf::OutputFile out(p.c_str(), header);
  out.setFrameBuffer(fb);
  out.writePixels(dhei);
}

void expect(const std::filesystem::path& p, ErrorClass cls, const std::vector<std::string>& says) {
  const auto t = thrown([&] { read_rendering(p); });
  ASSERT_TRUE(t.threw) << p << " was read without complaint";
  EXPECT_EQ(to_string(t.cls), to_string(cls)) << t.message;
  for (const auto& s : says) EXPECT_NE(t.message.find(s), std::string::npos) << "'" << s << "' not in: " << t.message;
  EXPECT_NE(t.message.find(p.filename().string()), std::string::npos) << "the message names no file: " << t.message;
}

TEST(VerifyIoBadInput, MissingEmptyAndForeignFiles) {
  TempDir dir;
  EXPECT_EQ(thrown([&] { read_rendering(dir / "none.exr"); }).cls, ErrorClass::io_error);
  write_bytes(dir / "empty.exr", "");
  expect(dir / "empty.exr", ErrorClass::bad_data, {"too short"});
  write_bytes(dir / "image.exr", "\x89PNG\r\n\x1a\n0000000000");  // a PNG named .exr: content decides
  expect(dir / "image.exr", ErrorClass::unsupported, {"not an OpenEXR"});
}

TEST(VerifyIoBadInput, TruncatedOpenExrAnywhere) {
  TempDir dir;
  std::vector<std::string> bands;
  for (int i = 0; i < 8; ++i) bands.push_back("S0." + std::to_string(400 + 40 * i) + "nm");
  write_exr(dir / "full.exr", bands, 64, 48, [](int x, int y, int c) { return static_cast<float>(x + y + c); });
  const std::string bytes = read_bytes(dir / "full.exr");
  ASSERT_NO_THROW(read_rendering(dir / "full.exr"));
  // Inside the header, at the line offset table, and in the middle and at the end of the pixel data.
  for (std::size_t cut : {std::size_t{12}, std::size_t{300}, bytes.size() / 2, bytes.size() - 1}) {
    write_bytes(dir / "cut.exr", bytes.substr(0, cut));
    SCOPED_TRACE("cut at " + std::to_string(cut) + " of " + std::to_string(bytes.size()));
    expect(dir / "cut.exr", ErrorClass::bad_data, {});
  }
}

TEST(VerifyIoBadInput, OpenExrWithMissingOrUnknownChannels) {
  TempDir dir;
  write_exr(dir / "rg.exr", {"R", "G"}, 4, 4);
  expect(dir / "rg.exr", ErrorClass::bad_data, {"B missing"});
  write_exr(dir / "xy.exr", {"X", "Y"}, 4, 4);
  expect(dir / "xy.exr", ErrorClass::bad_data, {"Z missing"});
  write_exr(dir / "foo.exr", {"depth", "normal.x"}, 4, 4);
  expect(dir / "foo.exr", ErrorClass::unsupported, {"depth", "normal.x"});
  write_exr(dir / "lum.exr", {"Y"}, 4, 4);  // a luminance-only image is not an incomplete XYZ one
  expect(dir / "lum.exr", ErrorClass::unsupported, {"Y"});
}

TEST(VerifyIoBadInput, SpectralBandNamesThatAreNotTheLayout) {
  TempDir dir;
  write_exr(dir / "dot.exr", {"S0.500nm", "S0.550.5nm"}, 4, 4);
  expect(dir / "dot.exr", ErrorClass::bad_data, {"S0.550.5nm", "JCGT"});
  write_exr(dir / "dup.exr", {"S0.550nm", "S0.550,0nm", "S0.0,55um"}, 4, 4);
  expect(dir / "dup.exr", ErrorClass::bad_data, {"same band centre"});
}

TEST(VerifyIoBadInput, ValuesLightCannotHaveAreFoundWithTheirPixelAndChannel) {
  TempDir dir;
  write_exr(dir / "nan.exr", {"S0.500nm", "S0.600nm"}, 8, 6,
            [](int x, int y, int c) { return x == 3 && y == 2 && c == 1 ? std::numeric_limits<float>::quiet_NaN() : 1.0f; });
  expect(dir / "nan.exr", ErrorClass::bad_data, {"NaN at pixel (3, 2) channel S0.600nm", "1 value(s)"});
  write_exr(dir / "neginf.exr", {"X", "Y", "Z"}, 8, 6,
            [](int x, int, int c) { return x >= 6 && c == 0 ? -std::numeric_limits<float>::infinity() : 1.0f; });
  expect(dir / "neginf.exr", ErrorClass::bad_data, {"-inf at pixel (6, 0) channel X", "12 value(s)"});
  write_exr(dir / "neg.exr", {"S0.500nm", "S0.600nm"}, 8, 6, [](int x, int y, int) { return x == 7 && y == 5 ? -0.5f : 1.0f; });
  expect(dir / "neg.exr", ErrorClass::bad_data, {"negative value", "(7, 5)"});
  write_exr(dir / "rgbinf.exr", {"R", "G", "B"}, 8, 6, [](int x, int, int) { return x == 1 ? std::numeric_limits<float>::infinity() : -1.0f; });
  expect(dir / "rgbinf.exr", ErrorClass::bad_data, {"+inf at pixel (1, 0) channel R"});
  write_exr(dir / "rgbneg.exr", {"R", "G", "B"}, 8, 6, [](int, int, int) { return -1.0f; });
  EXPECT_NO_THROW(read_rendering(dir / "rgbneg.exr"));  // out-of-gamut RGB is negative, legitimately
}

TEST(VerifyIoBadInput, OverscanDataWindowIsRefusedNotCropped) {
  TempDir dir;
  write_exr(dir / "over.exr", {"R", "G", "B"}, 4, 4, nullptr, Imath::Box2i({-1, 0}, {3, 3}));
  expect(dir / "over.exr", ErrorClass::unsupported, {"display window"});
}

std::string rgbe_line_10() {
  std::string line{2, 2, 0, 10};
  for (int comp = 0; comp < 4; ++comp) line += std::string{char(128 + 10), char(comp == 3 ? 130 : 5)};
  return line;
}

TEST(VerifyIoBadInput, RadianceFilesThatContradictThemselves) {
  TempDir dir;
  const std::string head = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 10\n";
  write_bytes(dir / "ok.hdr", head + rgbe_line_10() + rgbe_line_10());
  ASSERT_NO_THROW(read_rendering(dir / "ok.hdr"));
  write_bytes(dir / "short.hdr", head + rgbe_line_10() + rgbe_line_10().substr(0, 7));
  expect(dir / "short.hdr", ErrorClass::bad_data, {"scanline 1", "truncated"});
  write_bytes(dir / "long.hdr", head + rgbe_line_10() + rgbe_line_10() + "xx");
  expect(dir / "long.hdr", ErrorClass::bad_data, {"2 bytes after the last scanline"});
  std::string wrong_len = rgbe_line_10();
  wrong_len[3] = 9;
  write_bytes(dir / "len.hdr", head + wrong_len + rgbe_line_10());
  expect(dir / "len.hdr", ErrorClass::bad_data, {"scanline 0 says it is 9 pixels long, the header 10"});
  std::string overrun = rgbe_line_10();
  overrun[4] = char(128 + 11);
  write_bytes(dir / "run.hdr", head + overrun + rgbe_line_10());
  expect(dir / "run.hdr", ErrorClass::bad_data, {"overruns"});
  write_bytes(dir / "fmt.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgba\n\n-Y 1 +X 1\nabcd");
  expect(dir / "fmt.hdr", ErrorClass::bad_data, {"FORMAT=32-bit_rle_rgba"});
  write_bytes(dir / "res.hdr", "#?RADIANCE\n\nY 1 X 1\nabcd");
  expect(dir / "res.hdr", ErrorClass::bad_data, {"resolution line"});
  write_bytes(dir / "nohead.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n");
  expect(dir / "nohead.hdr", ErrorClass::bad_data, {"header ends"});
  write_bytes(dir / "exp.hdr", "#?RADIANCE\nEXPOSURE=-1\n\n-Y 1 +X 1\nabcd");
  expect(dir / "exp.hdr", ErrorClass::bad_data, {"EXPOSURE"});
  write_bytes(dir / "huge.hdr", "#?RADIANCE\n\n-Y 2000000000 +X 2000000000\n");
  expect(dir / "huge.hdr", ErrorClass::bad_data, {"exceeds"});
}

TEST(VerifyIoBadInput, PfmFilesThatContradictThemselves) {
  TempDir dir;
  const std::string px(2 * 2 * 3 * 4, '\0');
  write_bytes(dir / "ok.pfm", "PF\n2 2\n-1.0\n" + px);
  ASSERT_NO_THROW(read_rendering(dir / "ok.pfm"));
  write_bytes(dir / "short.pfm", "PF\n2 2\n-1.0\n" + px.substr(1));
  expect(dir / "short.pfm", ErrorClass::bad_data, {"truncated"});
  write_bytes(dir / "long.pfm", "PF\n2 2\n-1.0\n" + px + "\n");
  expect(dir / "long.pfm", ErrorClass::bad_data, {"48 bytes", "49"});
  write_bytes(dir / "zero.pfm", "PF\n2 2\n0\n" + px);
  expect(dir / "zero.pfm", ErrorClass::bad_data, {"scale is 0"});
  write_bytes(dir / "width.pfm", "PF\nabc 2\n-1.0\n" + px);
  expect(dir / "width.pfm", ErrorClass::bad_data, {"width 'abc'"});
  write_bytes(dir / "huge.pfm", "PF\n100000000 100000000\n-1.0\n" + px);
  expect(dir / "huge.pfm", ErrorClass::bad_data, {"exceeds"});
  std::string nan = px;
  const float q = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan.data() + 4 * 4, &q, 4);  // bottom row (stored first), pixel 1, channel G
  write_bytes(dir / "nan.pfm", "PF\n2 2\n-1.0\n" + nan);
  expect(dir / "nan.pfm", ErrorClass::bad_data, {"NaN at pixel (1, 1) channel G"});
}

}  // namespace
}  // namespace colorlab::verify
