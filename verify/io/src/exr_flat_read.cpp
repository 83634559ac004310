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

#include "io_detail.hpp"

namespace colorlab::verify::detail {

static_assert(std::endian::native == std::endian::little, "OpenEXR's bytes are copied as they are: little-endian hosts only");

namespace {

struct Wanted {
  std::size_t offset;  // of the channel's run of values within one scanline of a chunk, bytes
  std::size_t index;   // its place in the Rendering's pixel
};

// OpenEXR's ZIP chunk after inflating: bytes as differences (+128) and split into even and odd halves
// (OpenEXR's Zip::uncompress, the file format's definition). Undoes both into `out`.
void unpredict_and_interleave(unsigned char* t, std::size_t n, unsigned char* out) {
  for (std::size_t i = 1; i < n; ++i) t[i] = static_cast<unsigned char>(t[i - 1] + t[i] - 128);
  const unsigned char* a = t;
  const unsigned char* b = t + (n + 1) / 2;
  std::size_t i = 0;
  for (; i + 1 < n; i += 2) {
    out[i] = *a++;
    out[i + 1] = *b++;
  }
  if (i < n) out[i] = *a;
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
            bad_data(file, "the ZIP chunk at scanline " + std::to_string(y0) + " does not inflate to its " +
                               std::to_string(expected) + " bytes",
                     "the file is corrupt; write it again");
          unpredict_and_interleave(tmp.data(), expected, plain.data());
          chunk = plain.data();
        } else if (raw.size() != expected) {
          bad_data(file, "the chunk at scanline " + std::to_string(y0) + " holds " + std::to_string(raw.size()) +
                             " bytes, not the " + std::to_string(expected) + " its channels need",
                   "the file is corrupt; write it again");
        }
        // Little-endian on disk and in memory (x86-64, aarch64): a float's bytes copy as they are.
        for (std::size_t l = 0; l < lines; ++l) {
          char* row = base + static_cast<std::ptrdiff_t>(y0 + static_cast<long long>(l)) * static_cast<std::ptrdiff_t>(ys) +
                      static_cast<std::ptrdiff_t>(dw.min.x) * static_cast<std::ptrdiff_t>(xs);
          for (const auto& w : wanted) {
            const unsigned char* src = chunk + l * line_bytes + w.offset;
            char* dst = row + w.index * sizeof(float);
            for (std::size_t x = 0; x < width; ++x) std::memcpy(dst + x * xs, src + x * sizeof(float), sizeof(float));
          }
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
