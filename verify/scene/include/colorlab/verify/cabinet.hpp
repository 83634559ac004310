#pragma once
// The light cabinet as geometry (issue 23, docs/verify.md "The measured scene"): the inner box, one
// rectangular Lambertian emitter per lamp on the ceiling, the floor's reflectance. The exported scene and
// the simulator's geometric cabinet both read it, so a renderer and the simulated lab light the same box.
//
// Coordinates are the simulator's floor coordinates (docs/simulator.md): x from the left wall, y from the
// front edge, z up from the floor, all in mm. Emitters lie in the plane z = height_mm facing down.
#include <string>
#include <vector>

namespace colorlab::verify {

struct CabinetEmitter {
  std::string lamp;           // D65, TL84, CWF, A, UV (the lamp map's names)
  double x_mm = 0, y_mm = 0;  // centre of the emitting rectangle
  double length_mm = 0;       // along x (a tube's length)
  double width_mm = 0;        // along y
  // Luminance of the emitting surface at full output (cd/m²); 0 = unknown (a real lab: the export fits it
  // to the LS-110's floor readings).
  double luminance_cd_m2 = 0;
};

struct CabinetGeometry {
  // Width from the dissertation (appendix C.1: "of 120 cm width"); depth and height are not in the text and
  // are a Verivide-like assumption the lab configures.
  double width_mm = 1200.0;
  double depth_mm = 600.0;
  double height_mm = 600.0;
  double floor_reflectance = 0.30;  // the grey floor, Lambertian
  std::vector<CabinetEmitter> emitters;
  // The chart lies flat on the floor, centred here, its top edge (row 1 on an SG) towards the back: the
  // middle of the front region, where §6.2 concludes it belongs.
  double chart_center_x_mm = 600.0;
  double chart_center_y_mm = 140.0;
  // The LS-110 grid (cabinet-grid runs): spot (row r, col c) at ((c + ½)·pitch_x, (r + ½)·pitch_y), row 0 at
  // the front; 20 columns across the width and 8 rows of 54 mm (the simulator's floor grid).
  double grid_pitch_x_mm = 60.0;
  double grid_pitch_y_mm = 54.0;
};

// The default cabinet: the simulator's 1200 × 600 mm floor under a 600 mm ceiling, one diffuser panel per
// lamp, front to back D65, A, TL84, CWF, UV (the CWF panel is the middle one, where §6.2 finds its bright
// region). Emitter luminances give the §6.2 peak floor luminances in the field's brightest region.
CabinetGeometry default_cabinet();

// Throws Error(bad_parameter) naming the field and its allowed range: sizes must be positive, every emitter
// inside the ceiling, lamps known and not repeated, reflectance in [0, 1], luminance >= 0.
void validate(const CabinetGeometry& cabinet);

// The emitter of a lamp (case-insensitive name), or nullptr.
const CabinetEmitter* emitter_of(const CabinetGeometry& cabinet, const std::string& lamp);

// Configuration factor from a floor element at (x, y) (facing up) to an emitter (facing down) at height h:
// the fraction of the element's hemisphere the emitter fills, weighted by the cosine (closed form for a
// rectangle parallel to the element, by superposition of corner rectangles). A Lambertian emitter of
// luminance L gives the element the illuminance π·L·F, and a Lambertian floor of reflectance ρ the
// luminance ρ·L·F. Direct light only.
double form_factor(const CabinetEmitter& emitter, double height_mm, double x_mm, double y_mm);

}  // namespace colorlab::verify
