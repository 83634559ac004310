#pragma once
// Noise generation fast enough to add to 8 Mpixel frames in a few milliseconds: xoshiro256+ for bits and a
// 64 Ki-entry inverse-normal table (four Gaussian deviates per 64-bit draw, tails to ±4.3 σ — ample for
// sensor noise, which is what these deviates model).
#include <array>
#include <cstdint>
#include <vector>

namespace colorlab::sim::camera::detail {

constexpr std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

class Xoshiro256Plus {
 public:
  explicit Xoshiro256Plus(std::uint64_t seed) {
    for (auto& w : s_) w = seed = splitmix64(seed);
  }
  std::uint64_t operator()() {
    const std::uint64_t result = s_[0] + s_[3];
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = (s_[3] << 45) | (s_[3] >> 19);
    return result;
  }
  double uniform() { return double((*this)() >> 11) * 0x1.0p-53; }

 private:
  std::array<std::uint64_t, 4> s_{};
};

// Standard normal quantiles at (i + 0.5) / 65536.
const std::vector<float>& normal_table();

// Deterministic standard normal deviate from a hash (for fixed-pattern maps, one per pixel).
inline float hashed_normal(std::uint64_t key) { return normal_table()[splitmix64(key) & 0xFFFF]; }

}  // namespace colorlab::sim::camera::detail
