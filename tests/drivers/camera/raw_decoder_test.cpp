// LibRaw decoding through RawDecoder: exact round trip of the simulator's DNGs (against the
// counts it wrote and against `dcraw -D -4`), typed errors for bad input, and a real Canon CR2
// when one is provided through COLORLAB_CR2_FIXTURE.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/camera/raw_decoder.hpp"
#include "colorlab/sim/camera/dng.hpp"
#include "margin_dng.hpp"
#include "sim_fixture.hpp"

namespace cam = colorlab::drivers::camera;
namespace simcam = colorlab::sim::camera;
namespace fs = std::filesystem;
using colorlab::ErrorClass;

namespace {

std::vector<std::uint8_t> slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::size_t differing_counts(const cam::RawImage& img, const simcam::RawFrame& truth) {
  std::size_t wrong = 0;
  for (int y = 0; y < truth.height; ++y) {
    for (int x = 0; x < truth.width; ++x) {
      wrong += img.at(static_cast<std::size_t>(x), static_cast<std::size_t>(y)) != truth.at(x, y);
    }
  }
  return wrong;
}

std::string find_tool(const char* name) {
  for (const char* dir : {"/usr/bin/", "/usr/local/bin/"}) {
    const std::string p = std::string(dir) + name;
    if (fs::exists(p)) return p;
  }
  return {};
}

// `dcraw -D -4 -c` writes a 16-bit big-endian PGM of the visible area.
struct Pgm {
  std::size_t width = 0, height = 0;
  std::vector<std::uint16_t> pixels;
};

Pgm run_dcraw(const fs::path& raw_file) {
  const std::string cmd = find_tool("dcraw") + " -D -4 -c '" + raw_file.string() + "'";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  Pgm pgm;
  if (!pipe) return pgm;
  std::vector<std::uint8_t> out;
  std::uint8_t buf[65536];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) out.insert(out.end(), buf, buf + n);
  ::pclose(pipe);
  unsigned w = 0, h = 0, maxval = 0;
  int header = 0;
  if (std::sscanf(reinterpret_cast<const char*>(out.data()), "P5 %u %u %u%n", &w, &h, &maxval, &header) != 3) return pgm;
  const std::size_t start = static_cast<std::size_t>(header) + 1;
  if (out.size() < start + std::size_t(w) * h * 2) return pgm;
  pgm.width = w;
  pgm.height = h;
  pgm.pixels.resize(std::size_t(w) * h);
  for (std::size_t i = 0; i < pgm.pixels.size(); ++i) {
    pgm.pixels[i] = static_cast<std::uint16_t>(out[start + 2 * i] << 8 | out[start + 2 * i + 1]);
  }
  return pgm;
}

}  // namespace

TEST(camera_raw_decoder, simulator_dng_round_trips_exactly_from_file_and_memory) {
  cam::test::TempDir dir;
  auto model = cam::test::small_model();
  const simcam::RawFrame frame = model->render({}, 3);
  const fs::path file = dir.path() / "IMG_0001.DNG";
  simcam::write_dng(file, frame, {});

  cam::RawDecoder decoder;
  const cam::RawImage img = decoder.decode_file(file);
  EXPECT_EQ(img.width, static_cast<std::size_t>(frame.width));
  EXPECT_EQ(img.height, static_cast<std::size_t>(frame.height));
  EXPECT_EQ(img.left_margin, 0U);
  EXPECT_EQ(img.top_margin, 0U);
  EXPECT_EQ(img.cfa, cam::CfaPattern::rggb());
  EXPECT_EQ(img.white_level, frame.white_level);
  for (auto b : img.black_level) EXPECT_EQ(b, frame.black_level);
  EXPECT_EQ(img.bits_per_sample, 12U);
  EXPECT_EQ(differing_counts(img, frame), 0U);
  EXPECT_EQ(decoder.info().make, "colorlab");

  const auto bytes = slurp(file);
  const cam::RawImage from_memory = decoder.decode_buffer(bytes, "IMG_0001.DNG");
  EXPECT_EQ(differing_counts(from_memory, frame), 0U);
  EXPECT_EQ(from_memory.contiguous().size(), static_cast<std::size_t>(frame.width) * frame.height);
}

TEST(camera_raw_decoder, full_size_20d_frame_round_trips_exactly) {
  cam::test::TempDir dir;
  auto model = cam::test::small_model(3504, 2336);
  const simcam::RawFrame frame = model->render({}, 0);
  const fs::path file = dir.path() / "IMG_FULL.DNG";
  simcam::write_dng(file, frame, {});
  const cam::RawImage img = cam::RawDecoder::for_this_thread().decode_file(file);
  ASSERT_EQ(img.width, 3504U);
  ASSERT_EQ(img.height, 2336U);
  EXPECT_EQ(differing_counts(img, frame), 0U);  // 0 of 8,185,344
}

TEST(camera_raw_decoder, masked_margins_are_kept_and_skipped_like_dcraw) {
  cam::test::TempDir dir;
  cam::test::MarginDng d;
  d.raw_width = 180;
  d.raw_height = 124;
  d.top = 12;
  d.left = 10;
  d.bottom = 12 + 100;
  d.right = 10 + 160;
  d.pixels.resize(std::size_t(d.raw_width) * d.raw_height);
  for (std::uint32_t y = 0; y < d.raw_height; ++y) {
    for (std::uint32_t x = 0; x < d.raw_width; ++x) {
      const bool masked = y < d.top || y >= d.bottom || x < d.left || x >= d.right;
      d.pixels[y * d.raw_width + x] = static_cast<std::uint16_t>(masked ? 250 + (x + y) % 9 : 300 + (7 * x + 13 * y) % 3700);
    }
  }
  const fs::path file = dir.path() / "MARGINS.DNG";
  cam::test::write_margin_dng(file, d);

  cam::RawDecoder decoder;
  const cam::RawImage img = decoder.decode_file(file);
  EXPECT_EQ(img.raw_width, 180U);
  EXPECT_EQ(img.raw_height, 124U);
  EXPECT_EQ(img.left_margin, 10U);
  EXPECT_EQ(img.top_margin, 12U);
  EXPECT_EQ(img.width, 160U);
  EXPECT_EQ(img.height, 100U);
  EXPECT_EQ(img.cfa, cam::CfaPattern::rggb());
  EXPECT_EQ(img.black_at(0, 0), 256);
  std::size_t wrong_visible = 0, wrong_raw = 0;
  for (std::size_t y = 0; y < img.height; ++y) {
    for (std::size_t x = 0; x < img.width; ++x) {
      wrong_visible += img.at(x, y) != d.pixels[(y + d.top) * d.raw_width + x + d.left];
    }
  }
  for (std::size_t y = 0; y < img.raw_height; ++y) {
    for (std::size_t x = 0; x < img.raw_width; ++x) wrong_raw += img.pixels[y * img.row_stride + x] != d.pixels[y * d.raw_width + x];
  }
  EXPECT_EQ(wrong_visible, 0U);
  EXPECT_EQ(wrong_raw, 0U);  // the masked border stays available (dark reference)

  if (find_tool("dcraw").empty()) return;
  const Pgm pgm = run_dcraw(file);  // document mode writes the visible area only
  ASSERT_EQ(pgm.width, img.width);
  ASSERT_EQ(pgm.height, img.height);
  std::size_t wrong = 0;
  for (std::size_t y = 0; y < pgm.height; ++y) {
    for (std::size_t x = 0; x < pgm.width; ++x) wrong += img.at(x, y) != pgm.pixels[y * pgm.width + x];
  }
  EXPECT_EQ(wrong, 0U);
}

TEST(camera_raw_decoder, agrees_with_dcraw_document_mode) {
  if (find_tool("dcraw").empty()) GTEST_SKIP() << "dcraw not installed (apt-get install dcraw)";
  cam::test::TempDir dir;
  auto model = cam::test::small_model();
  const simcam::RawFrame frame = model->render({}, 5);
  const fs::path file = dir.path() / "IMG_0005.DNG";
  simcam::write_dng(file, frame, {});
  const Pgm pgm = run_dcraw(file);
  ASSERT_EQ(pgm.width, static_cast<std::size_t>(frame.width)) << "dcraw produced no PGM";
  cam::RawDecoder decoder;
  const cam::RawImage img = decoder.decode_file(file);
  std::size_t wrong = 0;
  for (std::size_t y = 0; y < pgm.height; ++y) {
    for (std::size_t x = 0; x < pgm.width; ++x) wrong += img.at(x, y) != pgm.pixels[y * pgm.width + x];
  }
  EXPECT_EQ(wrong, 0U);
}

TEST(camera_raw_decoder, bad_input_gives_typed_errors) {
  cam::test::TempDir dir;
  cam::RawDecoder decoder;
  try {
    decoder.decode_file(dir.path() / "missing.CR2");
    FAIL();
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::not_found);
  }
  try {
    decoder.decode_buffer({}, "empty download");
    FAIL();
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_data);
    EXPECT_NE(std::string(e.what()).find("empty download"), std::string::npos);
  }
  const std::vector<std::uint8_t> text(5000, 'x');
  try {
    decoder.decode_buffer(text, "IMG_0002.JPG");
    FAIL();
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_data);
    EXPECT_FALSE(e.hint().empty());
    EXPECT_EQ(e.info().device_code.rfind("libraw:", 0), 0U);
  }

  // A download cut short: header intact, pixel data missing.
  auto model = cam::test::small_model();
  const fs::path file = dir.path() / "IMG_0003.DNG";
  simcam::write_dng(file, model->render({}, 0), {});
  auto bytes = slurp(file);
  bytes.resize(bytes.size() * 9 / 10);
  try {
    decoder.decode_buffer(bytes, "truncated");
    FAIL() << "a truncated raw must not decode";
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_data) << e.what();
  }
}

TEST(camera_raw_decoder, real_canon_cr2_fixture) {
  const char* env = std::getenv("COLORLAB_CR2_FIXTURE");
  if (!env || !*env) GTEST_SKIP() << "set COLORLAB_CR2_FIXTURE=/path/to/IMG_xxxx.CR2 (a real EOS 20D raw) to run";
  if (!fs::exists(env)) GTEST_SKIP() << "COLORLAB_CR2_FIXTURE=" << env << " does not exist";
  cam::RawDecoder decoder;
  const cam::RawImage img = decoder.decode_file(env);
  EXPECT_EQ(decoder.info().make, "Canon");
  EXPECT_TRUE(img.cfa.is_mosaic());
  EXPECT_GT(img.width, 1000U);
  EXPECT_GE(img.raw_width, img.width + img.left_margin);
  EXPECT_GT(img.white_level, img.black_level[0]);
  if (find_tool("dcraw").empty()) return;
  const Pgm pgm = run_dcraw(env);
  ASSERT_EQ(pgm.width, img.width);
  ASSERT_EQ(pgm.height, img.height);
  std::size_t wrong = 0;
  for (std::size_t y = 0; y < pgm.height; ++y) {
    for (std::size_t x = 0; x < pgm.width; ++x) wrong += img.at(x, y) != pgm.pixels[y * pgm.width + x];
  }
  EXPECT_EQ(wrong, 0U);
}
