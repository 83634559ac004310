#include "exr_flat_read.hpp"

#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <libdeflate.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstring>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "io_detail.hpp"

namespace colorlab::verify::detail {

static_assert(std::endian::native == std::endian::little, "OpenEXR's bytes are copied as they are: little-endian hosts only");

namespace {

struct Wanted {
  std::size_t offset;  // of the channel's run of values within one scanline of a chunk, bytes
  std::size_t index;   // its place in the Rendering's pixel
};

// OpenEXR's ZIP chunk after inflating: each byte stored as its difference from the previous one, + 128, and the
// bytes split into the even-indexed half followed by the odd-indexed half (OpenEXR's Zip::uncompress, the format's
// definition). Undoes both into `out`. The running sum is the serial part, so it goes 16 bytes at a time: a prefix
// sum inside the vector by shifted adds, plus the previous vector's last byte (arithmetic mod 256 throughout).
void unpredict_and_interleave(unsigned char* t, std::size_t n, unsigned char* out) {
  if (n == 0) return;
  std::size_t i = 1;
#if defined(__SSE2__)
  // (t − 128) mod 256 is t ^ 0x80; byte 0 is stored as it is, so it starts the sum unflipped.
  __m128i carry = _mm_set1_epi8(static_cast<char>(t[0]));
  const __m128i flip = _mm_set1_epi8(static_cast<char>(0x80));
  for (; i + 16 <= n; i += 16) {
    __m128i v = _mm_xor_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(t + i)), flip);
    v = _mm_add_epi8(v, _mm_slli_si128(v, 1));
    v = _mm_add_epi8(v, _mm_slli_si128(v, 2));
    v = _mm_add_epi8(v, _mm_slli_si128(v, 4));
    v = _mm_add_epi8(v, _mm_slli_si128(v, 8));
    v = _mm_add_epi8(v, carry);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(t + i), v);
    carry = _mm_set1_epi8(static_cast<char>(t[i + 15]));
  }
#endif
  for (; i < n; ++i) t[i] = static_cast<unsigned char>(t[i - 1] + t[i] - 128);
  const unsigned char* a = t;
  const unsigned char* b = t + (n + 1) / 2;
  const std::size_t pairs = n / 2;
  std::size_t k = 0;
#if defined(__SSE2__)
  for (; k + 16 <= pairs; k += 16) {
    const __m128i va = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a + k));
    const __m128i vb = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + k));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 2 * k), _mm_unpacklo_epi8(va, vb));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 2 * k + 16), _mm_unpackhi_epi8(va, vb));
  }
#endif
  for (; k < pairs; ++k) {
    out[2 * k] = a[k];
    out[2 * k + 1] = b[k];
  }
  if (n % 2) out[n - 1] = a[pairs];
}

// One scanline's wanted channels into the Rendering's interleaved pixels (stride `xs` bytes per pixel).
void scatter(const unsigned char* line, const std::vector<Wanted>& wanted, std::size_t width, char* row, std::size_t xs) {
  for (const auto& w : wanted) {
    const unsigned char* src = line + w.offset;
    char* dst = row + w.index * sizeof(float);
    for (std::size_t x = 0; x < width; ++x) std::memcpy(dst + x * xs, src + x * sizeof(float), sizeof(float));
  }
}

}  // namespace

bool read_flat_float_scanlines(Imf::InputPart& in, const Imf::Header& header, const std::vector<std::string>& channels,
                               char* base, std::size_t xs, std::size_t ys, const std::filesystem::path& file) {
  if (header.hasTileDescription()) return false;
  int lines_per_chunk = 0;
  switch (header.compression()) {
    case Imf::NO_COMPRESSION:
    case Imf::ZIPS_COMPRESSION:
      lines_per_chunk = 1;
      break;
    case Imf::ZIP_COMPRESSION:
      lines_per_chunk = 16;
      break;
    default:
      return false;
  }
  const Imath::Box2i dw = header.dataWindow();
  const std::size_t width = static_cast<std::size_t>(static_cast<long long>(dw.max.x) - dw.min.x + 1);
  // A scanline holds every channel of the file, in the channel list's (name) order, each as a run of `width` values.
  std::size_t line_bytes = 0;
  std::vector<Wanted> wanted;
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
    const Imf::Channel& ch = it.channel();
    if (ch.xSampling != 1 || ch.ySampling != 1) return false;
    const std::size_t size = ch.type == Imf::HALF ? 2 : 4;
    const auto w = std::find(channels.begin(), channels.end(), std::string(it.name()));
    if (w != channels.end()) {
      if (ch.type != Imf::FLOAT) return false;
      wanted.push_back({line_bytes, static_cast<std::size_t>(w - channels.begin())});
    }
    line_bytes += size * width;
  }
  if (wanted.size() != channels.size()) return false;

  const long long height = static_cast<long long>(dw.max.y) - dw.min.y + 1;
  const long long chunks = (height + lines_per_chunk - 1) / lines_per_chunk;
  const int threads = static_cast<int>(std::clamp<long long>(std::thread::hardware_concurrency(), 1, std::min<long long>(16, chunks)));
  std::atomic<long long> next{0};
  std::mutex io;  // OpenEXR reads one chunk at a time from the file; inflating is what runs in parallel
  std::mutex failed;
  std::exception_ptr error;
  auto work = [&] {
    std::unique_ptr<libdeflate_decompressor, decltype(&libdeflate_free_decompressor)> inflater(
        libdeflate_alloc_decompressor(), &libdeflate_free_decompressor);
    std::vector<unsigned char> raw, tmp, plain;
    try {
      if (!inflater) throw std::bad_alloc();
      for (long long k = next++; k < chunks; k = next++) {
        {
          std::lock_guard<std::mutex> lock(failed);
          if (error) return;
        }
        const int y0 = static_cast<int>(dw.min.y + k * lines_per_chunk);
        const std::size_t lines = static_cast<std::size_t>(std::min<long long>(lines_per_chunk, dw.max.y - y0 + 1));
        const std::size_t expected = lines * line_bytes;
        {
          std::lock_guard<std::mutex> lock(io);
          const char* data = nullptr;
          int size = 0;
          in.rawPixelData(y0, data, size);
          raw.assign(reinterpret_cast<const unsigned char*>(data), reinterpret_cast<const unsigned char*>(data) + size);
        }
        const unsigned char* chunk = raw.data();
        // OpenEXR stores a chunk as it is when compressing would not make it smaller (and always without compression).
        if (raw.size() < expected && header.compression() != Imf::NO_COMPRESSION) {
          tmp.resize(expected);
          plain.resize(expected);
          std::size_t got = 0;
          if (libdeflate_zlib_decompress(inflater.get(), raw.data(), raw.size(), tmp.data(), expected, &got) !=
                  LIBDEFLATE_SUCCESS ||
              got != expected)
            bad_data(file,
                     "the ZIP chunk at scanline " + std::to_string(y0) + " does not inflate to its " +
                         std::to_string(expected) + " bytes",
                     "the file is corrupt; write it again");
          unpredict_and_interleave(tmp.data(), expected, plain.data());
          chunk = plain.data();
        } else if (raw.size() != expected) {
          bad_data(file,
                   "the chunk at scanline " + std::to_string(y0) + " holds " + std::to_string(raw.size()) +
                       " bytes, not the " + std::to_string(expected) + " its channels need",
                   "the file is corrupt; write it again");
        }
        // Little-endian on disk and in memory (x86-64, aarch64): a float's bytes copy as they are.
        for (std::size_t l = 0; l < lines; ++l) {
          char* row = base + static_cast<std::ptrdiff_t>(y0 + static_cast<long long>(l)) * static_cast<std::ptrdiff_t>(ys) +
                      static_cast<std::ptrdiff_t>(dw.min.x) * static_cast<std::ptrdiff_t>(xs);
          scatter(chunk + l * line_bytes, wanted, width, row, xs);
        }
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(failed);
      if (!error) error = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  return true;
}

}  // namespace colorlab::verify::detail
