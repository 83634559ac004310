#pragma once
// Lamp spectra (from colord's CIE tables) and the photopic weighting used to put them on an absolute scale.
#include "colorlab/sim/scene.hpp"

namespace colorlab::sim::detail {

// Peak-normalised relative SPD on colord's native 5 nm grid (the UV tube is a modelled near-UV band).
Spectrum load_lamp_spectrum(Lamp lamp);

// CIE 1931 2° ȳ from colord's CMF table.
Spectrum load_y_bar();

// Σ S(λ) ȳ(λ) Δλ over the overlap of both grids, sampled on `s`'s grid.
double photopic_integral(const Spectrum& s, const Spectrum& y_bar);

}  // namespace colorlab::sim::detail
