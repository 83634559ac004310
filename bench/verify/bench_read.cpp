// Reading a renderer's images (issue 23): a 36-band spectral OpenEXR at 1752 × 1168 (half the photograph's size,
// about 300 MB of float) read by colorlab and by Debian's oiiotool in the same run, interleaved A B A B so both
// see the same machine load; and an RGB OpenEXR at the photograph's 3504 × 2336. The target: our spectral
// read at ≥ 50 % of oiiotool's speed, i.e. ratio = oiiotool time / our time ≥ 0.5.
//
//   bench_verify_read [--rounds N] [--dir DIR]      (docs/PERFORMANCE.md "Reading renderings")
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "colorlab/verify/rendering.hpp"
#include "colorlab/verify/rendering_xyz.hpp"

namespace {

using colorlab::verify::Encoding;
using colorlab::verify::Rendering;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// Smooth spectra that vary across the image plus a render's per-pixel noise (1 %), so the file compresses like a
// path-traced image rather than like a constant.
float noise(std::uint32_t i) {
  i ^= i >> 16;
  i *= 0x7feb352dU;
  i ^= i >> 15;
  i *= 0x846ca68bU;
  i ^= i >> 16;
  return static_cast<float>(i) / 4294967296.0f - 0.5f;
}

Rendering spectral_image(int w, int h) {
  Rendering r;
  r.encoding = Encoding::spectral;
  r.width = w;
  r.height = h;
  r.units = "W.m^-2.sr^-1";
  for (int b = 0; b < 36; ++b) r.wavelengths_nm.push_back(380.0 + 10.0 * b);
  r.pixels.resize(static_cast<std::size_t>(w) * h * 36);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double u = double(x) / w, v = double(y) / h;
      for (int b = 0; b < 36; ++b) {
        const std::size_t i = (static_cast<std::size_t>(y) * w + x) * 36 + b;
        const double s = 0.02 + 0.01 * std::sin(6 * u + b * 0.2) * std::cos(4 * v) + 0.005 * b / 36.0;
        r.pixels[i] = static_cast<float>(s * (1.0 + 0.01 * noise(static_cast<std::uint32_t>(i))));
      }
    }
  return r;
}

Rendering rgb_image(int w, int h) {
  Rendering r;
  r.encoding = Encoding::rgb;
  r.width = w;
  r.height = h;
  r.chromaticities = colorlab::verify::rec709_chromaticities();
  r.pixels.resize(static_cast<std::size_t>(w) * h * 3);
  for (std::size_t i = 0; i < r.pixels.size(); ++i)
    r.pixels[i] = static_cast<float>(0.3 + 0.2 * std::sin(double(i % 9000) * 1e-3)) * (1.0f + 0.01f * noise(static_cast<std::uint32_t>(i)));
  return r;
}

double ours(const std::filesystem::path& f, std::size_t* floats) {
  const auto t0 = Clock::now();
  Rendering r = colorlab::verify::read_rendering(f);
  const double t = seconds_since(t0);
  *floats = r.pixels.size();
  return t;
}

// oiiotool's `-i:now=1` reads the whole image into memory at once (no lazy ImageCache); the wall time includes
// starting the process, measured separately on a 1 × 1 file.
double oiiotool(const std::filesystem::path& f) {
  const std::string cmd = "oiiotool -i:now=1 '" + f.string() + "' >/dev/null 2>&1";
  const auto t0 = Clock::now();
  const int rc = std::system(cmd.c_str());
  const double t = seconds_since(t0);
  if (rc != 0) {
    std::fprintf(stderr, "oiiotool failed on %s (is openimageio-tools installed?)\n", f.c_str());
    std::exit(1);
  }
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  int rounds = 5;
  std::filesystem::path dir = std::filesystem::temp_directory_path() / "colorlab_bench_verify_read";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--rounds") rounds = std::max(1, std::atoi(argv[i + 1]));
    else if (a == "--dir") dir = argv[i + 1];
  }
  std::filesystem::create_directories(dir);
  const auto spectral = dir / "spectral_36x1752x1168.exr", rgb = dir / "rgb_3504x2336.exr", tiny = dir / "tiny.exr";
  {
    auto t0 = Clock::now();
    Rendering s = spectral_image(1752, 1168);
    colorlab::verify::write_openexr(s, spectral);
    std::printf("wrote %s (%.0f MB on disk, %.0f MB float) in %.2f s\n", spectral.c_str(),
                std::filesystem::file_size(spectral) / 1e6, s.pixels.size() * 4 / 1e6, seconds_since(t0));
    t0 = Clock::now();
    Rendering x = colorlab::verify::to_xyz(s);
    std::printf("to_xyz of the spectral image: %.3f s\n", seconds_since(t0));
    colorlab::verify::write_openexr(rgb_image(3504, 2336), rgb);
    colorlab::verify::write_openexr(rgb_image(1, 1), tiny);
  }
  std::vector<double> a, b, c, d, start;
  std::size_t floats = 0;
  for (int r = 0; r < rounds; ++r) {
    a.push_back(ours(spectral, &floats));
    b.push_back(oiiotool(spectral));
    c.push_back(ours(rgb, &floats));
    d.push_back(oiiotool(rgb));
    start.push_back(oiiotool(tiny));
    std::printf("round %d: spectral ours %.3f s, oiiotool %.3f s | rgb ours %.3f s, oiiotool %.3f s | oiiotool 1x1 %.3f s\n", r + 1,
                a.back(), b.back(), c.back(), d.back(), start.back());
  }
  std::printf(
      "spectral 36 x 1752 x 1168 (median of %d): ours %.3f s, oiiotool %.3f s (start-up %.3f s): ratio %.2f "
      "(target >= 0.50), %.2f without oiiotool's start-up\n",
      rounds, median(a), median(b), median(start), median(b) / median(a), (median(b) - median(start)) / median(a));
  std::printf("rgb 3504 x 2336 (median of %d): ours %.3f s, oiiotool %.3f s\n", rounds, median(c), median(d));
  std::filesystem::remove(spectral);
  std::filesystem::remove(rgb);
  std::filesystem::remove(tiny);
  return 0;
}
