// verify/io's own decoder of flat float scanline files (exr_flat_read: uncompressed, ZIPS, ZIP) against OpenEXR's
// frame-buffer path reading the same file — the library that wrote it is the reference, bit for bit. The files
// are made to reach every corner of the decoder: odd widths (an odd byte count in the ZIP interleave), a partial
// last chunk, a data window inside the display window, channels the Rendering does not want (a HALF one between
// the wanted ones), bytes that wrap in the predictor, and random bits no compressor can shrink (stored chunks).
#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <half.h>

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "colorlab/core/error.hpp"
#include "colorlab/verify/rendering.hpp"

namespace {

namespace fs = std::filesystem;
using colorlab::verify::read_rendering;

struct Case {
  Imf::Compression compression;
  int width, height;
  Imath::Box2i data;  // inside the display window [0, width) × [0, height)
  bool noisy;         // random mantissas: chunks that do not compress
};

fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / ("colorlab_flat_read_" + std::to_string(::getpid()) + "_" + name + ".exr");
}

// Writes X, Y, Z (FLOAT) and A (HALF, not wanted: it sorts first, so every wanted channel sits behind it) and
// returns what OpenEXR's own frame-buffer path reads back for X, Y, Z over the display window (0 outside the data).
std::vector<float> write_and_reference(const fs::path& file, const Case& c, std::uint32_t seed) {
  Imf::Header h(Imath::Box2i({0, 0}, {c.width - 1, c.height - 1}), c.data);
  h.compression() = c.compression;
  for (const char* n : {"X", "Y", "Z"}) h.channels().insert(n, Imf::Channel(Imf::FLOAT));
  h.channels().insert("A", Imf::Channel(Imf::HALF));
  const int dw = c.data.max.x - c.data.min.x + 1, dh = c.data.max.y - c.data.min.y + 1;
  std::vector<float> xyz(static_cast<std::size_t>(dw) * dh * 3);
  std::vector<Imath::half> a(static_cast<std::size_t>(dw) * dh);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1000.0f);
  for (std::size_t i = 0; i < xyz.size(); ++i) xyz[i] = c.noisy ? u(rng) : 50.0f + static_cast<float>(i % 97) * 0.25f;
  for (std::size_t i = 0; i < a.size(); ++i) a[i] = static_cast<float>(i % 13);
  {
    Imf::OutputFile out(file.c_str(), h);
    Imf::FrameBuffer fb;
    char* base = reinterpret_cast<char*>(xyz.data()) -
                 (static_cast<std::ptrdiff_t>(c.data.min.x) + static_cast<std::ptrdiff_t>(c.data.min.y) * dw) * 12;
    for (int k = 0; k < 3; ++k)
      fb.insert(std::string(1, "XYZ"[k]), Imf::Slice(Imf::FLOAT, base + 4 * k, 12, static_cast<std::size_t>(dw) * 12));
    fb.insert("A", Imf::Slice(Imf::HALF,
                              reinterpret_cast<char*>(a.data()) -
                                  (static_cast<std::ptrdiff_t>(c.data.min.x) + static_cast<std::ptrdiff_t>(c.data.min.y) * dw) * 2,
                              2, static_cast<std::size_t>(dw) * 2));
    out.setFrameBuffer(fb);
    out.writePixels(dh);
  }
  std::vector<float> ref(static_cast<std::size_t>(c.width) * c.height * 3, 0.0f);
  Imf::InputFile in(file.c_str());
  Imf::FrameBuffer fb;
  for (int k = 0; k < 3; ++k)
    fb.insert(std::string(1, "XYZ"[k]), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(ref.data()) + 4 * k, 12,
                                                   static_cast<std::size_t>(c.width) * 12));
  in.setFrameBuffer(fb);
  in.readPixels(c.data.min.y, c.data.max.y);
  return ref;
}

void expect_same(const Case& c, const std::string& name, std::uint32_t seed) {
  const fs::path file = temp_file(name);
  const std::vector<float> ref = write_and_reference(file, c, seed);
  const auto r = read_rendering(file);
  fs::remove(file);
  ASSERT_EQ(r.encoding, colorlab::verify::Encoding::xyz);
  ASSERT_EQ(r.width, c.width);
  ASSERT_EQ(r.height, c.height);
  ASSERT_EQ(r.pixels.size(), ref.size());
  std::size_t differ = 0, first = ref.size();
  for (std::size_t i = 0; i < ref.size(); ++i)
    if (std::memcmp(&r.pixels[i], &ref[i], sizeof(float)) != 0) {
      ++differ;
      if (first == ref.size()) first = i;
    }
  EXPECT_EQ(differ, 0u) << name << ": first at float " << first << " (ours " << r.pixels[first] << ", OpenEXR's "
                        << ref[first] << ")";
}

TEST(VerifyIoFlatRead, EveryCompressionItDecodesAgreesWithOpenExrBitForBit) {
  const Imath::Box2i full({0, 0}, {36, 40});
  for (bool noisy : {false, true}) {
    expect_same({Imf::NO_COMPRESSION, 37, 41, full, noisy}, "none", 1);
    expect_same({Imf::ZIPS_COMPRESSION, 37, 41, full, noisy}, "zips", 2);
    expect_same({Imf::ZIP_COMPRESSION, 37, 41, full, noisy}, "zip", 3);  // 41 lines: a last chunk of 9
    // Not ours to decode (PIZ): OpenEXR's path, the same answer.
    expect_same({Imf::PIZ_COMPRESSION, 37, 41, full, noisy}, "piz", 4);
  }
}

TEST(VerifyIoFlatRead, DataWindowInsideTheDisplayWindowLandsWhereItBelongs) {
  expect_same({Imf::ZIP_COMPRESSION, 64, 50, Imath::Box2i({5, 7}, {40, 44}), false}, "window_zip", 5);
  expect_same({Imf::NO_COMPRESSION, 64, 50, Imath::Box2i({1, 0}, {63, 18}), true}, "window_none", 6);
}

TEST(VerifyIoFlatRead, AWideImageSpansManyChunksAndThreads) {
  // 1 + 16·k lines, wider than a vector: the SIMD running sum's carry crosses thousands of 16-byte blocks.
  expect_same({Imf::ZIP_COMPRESSION, 1001, 97, Imath::Box2i({0, 0}, {1000, 96}), false}, "wide_zip", 7);
  expect_same({Imf::ZIP_COMPRESSION, 1001, 97, Imath::Box2i({0, 0}, {1000, 96}), true}, "wide_zip_noisy", 8);
}

TEST(VerifyIoFlatRead, ACorruptZipChunkIsBadDataNamingTheFile) {
  const Case c{Imf::ZIP_COMPRESSION, 37, 41, Imath::Box2i({0, 0}, {36, 40}), false};
  const fs::path file = temp_file("corrupt");
  write_and_reference(file, c, 9);
  // Flip bytes in the middle of the chunk data (past the header and offset table): the zlib stream breaks.
  {
    std::FILE* f = std::fopen(file.c_str(), "r+b");
    ASSERT_NE(f, nullptr);
    std::fseek(f, 0, SEEK_END);
    const long size = std::ftell(f);
    for (long at = size / 2; at < size / 2 + 24; ++at) {
      std::fseek(f, at, SEEK_SET);
      std::fputc(0xA5, f);
    }
    std::fclose(f);
  }
  try {
    (void)read_rendering(file);
    ADD_FAILURE() << "a corrupt chunk was read";
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), colorlab::ErrorClass::bad_data) << e.what();
    EXPECT_NE(std::string(e.what()).find(file.filename().string()), std::string::npos) << e.what();
  }
  fs::remove(file);
}

}  // namespace
