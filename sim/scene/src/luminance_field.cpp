#include "luminance_field.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace colorlab::sim::detail {

double dimmer_output(double percent) {
  // Phase-cut dimmers on fluorescent ballasts: nothing below 1 %, and below full power the ballast loses a
  // roughly constant ~13 % of efficiency, so the light is not directly proportional to the setting
  // (§6.2: the dimmer-scaled differences miss the 100 % field by 18–25 cd/m²).
  if (percent < 1.0) return 0.0;
  const double d = std::min(percent, 100.0) / 100.0;
  return d * (0.87 + 0.13 * d * d * d);
}

namespace {
constexpr double grid_depth_mm = floor_rows * floor_spot_pitch_y_mm;
}

LuminanceField::LuminanceField(Lamp lamp, std::uint64_t seed) {
  // Kept as laid out by hand: one lamp a row.
  // clang-format off
  switch (lamp) {
    case Lamp::d65:  peak_ = 322; side_ = 0.33; depth_ = 0.12; cross_ = 0.05; centre_y_ = 0.0; flatten_ = 0.03; break;
    // TL84 and CWF tubes in this cabinet are older and sit differently: steeper side fall-off (TL84) and a
    // bright region in the middle of the cabinet rather than at the front (CWF), as §6.2 reports.
    case Lamp::tl84: peak_ = 345; side_ = 0.40; depth_ = 0.24; cross_ = 0.06; centre_y_ = 0.0; flatten_ = 0.03; break;
    case Lamp::cwf:  peak_ = 300; side_ = 0.44; depth_ = 0.50; cross_ = 0.05; centre_y_ = 0.45; flatten_ = 0.03; break;
    case Lamp::a:    peak_ = 240; side_ = 0.26; depth_ = 0.14; cross_ = 0.03; centre_y_ = 0.0; flatten_ = 0.02; break;
    case Lamp::uv:   peak_ = 4.0; side_ = 0.30; depth_ = 0.15; cross_ = 0.04; centre_y_ = 0.0; flatten_ = 0.0; break;
  }
  // clang-format on
  std::mt19937_64 rng(seed ^ (0x9E3779B97F4A7C15ull * (static_cast<std::uint64_t>(lamp) + 1)));
  std::uniform_real_distribution<double> ux(100.0, cabinet_width_mm - 100.0), uy(0.0, grid_depth_mm),
      us(120.0, 220.0), ua(-0.012, 0.012);
  for (auto& b : bumps_) b = {ux(rng), uy(rng), us(rng), ua(rng)};
}

LuminanceField::LuminanceField(const verify::CabinetEmitter* emitter, double height_mm, double floor_reflectance)
    : geometric_(true), height_mm_(height_mm), floor_reflectance_(floor_reflectance) {
  if (emitter) emitter_ = *emitter;
}

double LuminanceField::at(double x_mm, double y_mm, double dimmer_percent) const {
  const double out = dimmer_output(dimmer_percent);
  if (out <= 0.0) return 0.0;
  if (geometric_) {
    if (!emitter_) return 0.0;
    return out * floor_reflectance_ * emitter_->luminance_cd_m2 * verify::form_factor(*emitter_, height_mm_, x_mm, y_mm);
  }
  const double u = (x_mm - cabinet_width_mm / 2) / (cabinet_width_mm / 2);
  const double v = y_mm / grid_depth_mm;
  // Dimmed tubes emit more evenly along their length, so the relative shape flattens a little.
  const double k = 1.0 - flatten_ * (1.0 - dimmer_percent / 100.0);
  const double dv = centre_y_ > 0 ? 2.0 * (v - centre_y_) * (v - centre_y_) / (1.0 - centre_y_) : v;
  double g = 1.0 - k * (side_ * u * u + depth_ * dv + cross_ * u * u * v);
  for (const auto& b : bumps_) {
    const double r2 = ((x_mm - b.x) * (x_mm - b.x) + (y_mm - b.y) * (y_mm - b.y)) / (b.sigma * b.sigma);
    g += b.amplitude * std::exp(-0.5 * r2);
  }
  return peak_ * out * std::max(g, 0.05);
}

}  // namespace colorlab::sim::detail
