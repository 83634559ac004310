#pragma once
// The floor luminance field of one lamp: a smooth shape fitted to the dissertation's §6.2 measurements
// (brightest at the middle front, falling towards the side walls and the back) plus a few seeded,
// percent-level bumps so that different seeds give different but equally plausible cabinets.
#include <array>
#include <cstdint>
#include <optional>

#include "colorlab/sim/scene.hpp"
#include "colorlab/verify/cabinet.hpp"

namespace colorlab::sim::detail {

// Light output relative to 100 % for a dimmer setting (0..100).
double dimmer_output(double percent);

class LuminanceField {
 public:
  LuminanceField(Lamp lamp, std::uint64_t seed);
  // The geometric cabinet's field: the floor lit directly by the lamp's Lambertian emitter (the analytic form
  // factor), ρ·L·F; no emitter (nullptr) gives a lamp that lights nothing.
  LuminanceField(const verify::CabinetEmitter* emitter, double height_mm, double floor_reflectance);
  // cd/m² on the grey floor at (x, y) mm with this lamp alone, fully warm.
  double at(double x_mm, double y_mm, double dimmer_percent) const;

 private:
  struct Bump {
    double x, y, sigma, amplitude;
  };
  double peak_ = 0;      // cd/m² at the brightest point, 100 %
  double side_ = 0;      // fall-off towards the side walls (quadratic in x)
  double depth_ = 0;     // fall-off towards the back (linear in y)
  double cross_ = 0;     // extra fall-off in the back corners
  double centre_y_ = 0;  // depth of the brightest line as a fraction of the grid depth (0 = front)
  double flatten_ = 0;   // how much the relative shape flattens as the dimmer goes down
  std::array<Bump, 3> bumps_{};
  bool geometric_ = false;
  std::optional<verify::CabinetEmitter> emitter_;
  double height_mm_ = 0, floor_reflectance_ = 0;
};

}  // namespace colorlab::sim::detail
