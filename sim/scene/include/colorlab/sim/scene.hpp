#pragma once
// The physics every simulated instrument reads from: a Verivide-like light cabinet (five lamps, a dimmer,
// warm-up drift, a non-uniform floor field shaped like the dissertation's §6.2 measurements), the
// 140-patch ColorChecker SG placed in it, and the white tile. Deterministic for a seed; thread-safe.
//
// Coordinates: cabinet floor in mm, x from the left wall (0..1200), y from the front edge (0..depth).
// The LS-110 floor grid is 8 rows × 20 columns of spots, row 0 at the front.
#include <array>
#include <utility>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "colorlab/sim/clock.hpp"
#include "colorlab/sim/spectrum.hpp"
#include "colorlab/verify/cabinet.hpp"

namespace colorlab::sim {

enum class Lamp {
  d65,
  tl84,
  cwf,
  a,
  uv
};
inline constexpr std::array<Lamp, 5> all_lamps{Lamp::d65, Lamp::tl84, Lamp::cwf, Lamp::a, Lamp::uv};

std::string_view to_string(Lamp lamp);  // "D65", "TL84", "CWF", "A", "UV"
// Accepts D65, TL84, F11, 840, CWF, F2, A, UV (case-insensitive); throws Error(bad_parameter).
Lamp lamp_from_string(std::string_view name);

inline constexpr int floor_rows = 8;
inline constexpr int floor_cols = 20;
inline constexpr double cabinet_width_mm = 1200.0;
inline constexpr double floor_spot_pitch_x_mm = cabinet_width_mm / floor_cols;  // 60 mm
inline constexpr double floor_spot_pitch_y_mm = 54.0;
inline constexpr double cabinet_depth_mm = 600.0;

inline constexpr int chart_patch_count = 140;  // ColorChecker SG: columns A..N, rows 1..10
inline constexpr int chart_columns = 14;
inline constexpr int chart_rows = 10;
inline constexpr double chart_width_mm = 279.4;
inline constexpr double chart_height_mm = 215.9;

// SpectroScan T table: 310 × 230 mm, origin at its top-left corner, x right, y towards the operator.
inline constexpr double table_width_mm = 310.0;
inline constexpr double table_height_mm = 230.0;

struct SceneConfig {
  std::uint64_t seed = 1;
  // Chart spectra: CSV (wavelength_nm,A1..N10) or CGATS with SPEC_nnn fields and SAMPLE_ID. When unset, the
  // shared data set's pre-2014 X-Rite SG spectra are used when present, else a built-in synthetic chart.
  std::optional<std::filesystem::path> chart_file;
  bool force_synthetic_chart = false;
  // Chart centre on the cabinet floor (default: the middle of the front region, as §6.2 concludes).
  double chart_center_x_mm = 600.0;
  double chart_center_y_mm = 140.0;
  // Where the chart's top-left corner lies on the SpectroScan T table (mm); the chart is centred by default.
  double chart_on_table_x_mm = (table_width_mm - chart_width_mm) / 2.0;
  double chart_on_table_y_mm = (table_height_mm - chart_height_mm) / 2.0;
  // Warm-up: a lamp switched on starts at warmup_start_fraction of its output (fluorescent tubes) and
  // approaches 1 with time constant warmup_tau_s simulated seconds (tungsten A is ten times faster).
  double warmup_start_fraction = 0.85;
  double warmup_tau_s = 120.0;
  // Lamps already warm at construction (switched on long ago), e.g. {Lamp::d65}.
  std::vector<Lamp> lamps_on_at_start;
  double dimmer_percent_at_start = 100.0;
  // Opt-in: a cabinet whose floor light comes from its geometry (each lamp's rectangular Lambertian emitter,
  // direct light only, black walls: the analytic form factor of verify::form_factor) instead of the
  // §6.2-shaped field the dissertation's tables rest on. Its floor_reflectance must be the simulated floor's
  // 0.30 and every emitter's luminance known (> 0); a lamp without an emitter lights nothing. The chart
  // lies at the cabinet's chart_center_mm (it replaces chart_center_x/y_mm); the floor keeps its 1200 × 600 mm
  // and its grid. docs/verify.md, "The measured scene".
  std::optional<verify::CabinetGeometry> geometric_cabinet;
};

// A lamp whose light output drifts (docs/simulator.md, "Cabinet" faults). From `start_s` (simulated seconds)
// its output changes linearly by `rate_per_s` (a fraction of its normal output per simulated second;
// negative = dimmer) for `duration_s`; then it holds that level (`returns` false: a tube that has settled at
// a new thermal equilibrium, or aged) or comes back at the same rate and is normal again after another
// `duration_s` (`returns` true: the overheating clears). The drift follows simulated time whether the lamp
// is lit or not, and multiplies whatever the warm-up gives.
struct LampDrift {
  double start_s = 0;
  double rate_per_s = 0;
  double duration_s = 0;
  bool returns = false;
  // Output multiplier at simulated time t (1 before the start; never below 0).
  double factor_at(double t) const;
};

struct ChartPatch {
  std::string name;  // "A1".."N10"
  int column = 0;    // 0..13 (A..N)
  int row = 0;       // 0..9  (1..10)
  // Patch square in chart coordinates, mm from the chart's top-left corner (x right, y down).
  double x_mm = 0, y_mm = 0, size_mm = 0;
  Spectrum reflectance;  // 380–730 nm, 10 nm
};

struct Chart {
  std::string source;               // file path or "synthetic"
  std::vector<ChartPatch> patches;  // 140, in A1, A2, ..., A10, B1, ... order
  // Index of the patch containing chart point (x_mm, y_mm), or nullopt (border/gap).
  std::optional<int> patch_at(double x_mm, double y_mm) const;
  std::optional<int> index_of(std::string_view name) const;
};

class Scene {
 public:
  Scene(SceneConfig config, std::shared_ptr<const SimClock> clock);
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  // ---- lamps and dimmer (DMX / relay servers write these) ----
  void set_lamp(Lamp lamp, bool on);
  bool lamp_on(Lamp lamp) const;
  std::vector<Lamp> lamps_on() const;
  void set_dimmer(double percent);  // 0..100; throws Error(bad_parameter) outside
  double dimmer() const;
  // Relative light output of the dimmer (1 at 100 %, non-proportional below, 0 at 0 %).
  static double dimmer_output(double percent);
  // Multiplier in (0,1] from warm-up since the lamp was last switched on (1 when off or warm).
  double warmup_factor(Lamp lamp) const;
  // Starts (or replaces) a drift of the lamp's output; a zero rate or duration clears it.
  void set_lamp_drift(Lamp lamp, const LampDrift& drift);
  // Multiplier of the lamp's output from its drift now (1 = none, or over and returned).
  double drift_factor(Lamp lamp) const;
  // The lamp's output relative to normal now: warm-up × drift (what every instrument sees).
  double output_factor(Lamp lamp) const;
  // Monotonic counter bumped by every lamp/dimmer change (lets renderers cache per state).
  std::uint64_t state_version() const;

  // ---- luminance field (LS-110 reads these) ----
  // True floor luminance in cd/m² at grid spot (row 0..7 front first, col 0..19), current lamps, dimmer,
  // warm-up and drift, no noise. Throws Error(bad_parameter) for spots off the grid.
  double floor_luminance(int row, int col) const;
  // The same at any floor point (mm).
  double floor_luminance_at(double x_mm, double y_mm) const;
  // Floor luminance of one lamp alone at full warm-up and the given dimmer, for analysis and tests.
  double lamp_floor_luminance(Lamp lamp, double dimmer_percent, double x_mm, double y_mm) const;
  static std::pair<double, double> floor_spot_position_mm(int row, int col);
  // LS-110 measurement repeatability (1 σ, cd/m²) at a luminance.
  double luminance_noise_sigma(double cd_m2) const;

  // ---- spectra ----
  // Relative SPD of a lamp (colord CIE tables on their 5 nm grid, UV a near-UV band), peak-normalised to 1.
  const Spectrum& lamp_spectrum(Lamp lamp) const;
  // Spectral radiance (W·sr⁻¹·m⁻²·nm⁻¹, 380–730 nm, 5 nm) leaving a Lambertian surface with the given
  // reflectance at floor point (x, y) under the current lamps, dimmer, warm-up and drift.
  Spectrum spectral_radiance(double x_mm, double y_mm, const Spectrum& reflectance) const;
  // Spectral irradiance-like quantity per unit reflectance: spectral_radiance of a perfect white.
  Spectrum white_radiance(double x_mm, double y_mm) const;
  // Spectral radiance (380–730 nm, 5 nm) of a surface with this reflectance lit by one lamp at the strength
  // that gives the grey floor a luminance of 1 cd/m²: multiply by lamp_floor_luminance × output_factor.
  Spectrum lamp_radiance_per_cd(Lamp lamp, const Spectrum& reflectance) const;
  // Truth for colorimetry: a chart patch's CIE 1931 XYZ (absolute, Y in cd/m²) under the current lamps at its
  // place in the cabinet, and its L*a*b* relative to a perfect white at the same place.
  std::array<double, 3> patch_xyz(int patch_index) const;
  std::array<double, 3> patch_lab(int patch_index) const;
  // Floor material reflectance (a flat mid grey).
  static double floor_reflectance() { return 0.30; }

  // ---- chart, white tile, transmission sample (Spectrolino/SpectroScan read these) ----
  const Chart& chart() const;
  // Chart patch centre on the cabinet floor (mm).
  std::pair<double, double> patch_floor_position_mm(int patch_index) const;
  // Floor point (mm) of a chart point (mm from the chart's top-left corner; chart top edge is at the back).
  std::pair<double, double> chart_to_floor_mm(double chart_x_mm, double chart_y_mm) const;
  // What the Spectrolino's aperture sees at table point (x, y) mm: a chart patch, the chart's dark surround,
  // or the table's off-white paper-hold plate. Throws Error(bad_parameter) off the table.
  struct TableSample {
    std::optional<int> patch;               // chart patch index when on a patch
    const Spectrum* reflectance = nullptr;  // owned by the scene
  };
  TableSample table_sample(double x_mm, double y_mm) const;
  // Spectrolino white calibration tile (its certified reflectance, 380–730/10 nm).
  const Spectrum& white_tile() const;
  // A neutral-density-plus-colour filter for transmission mode (380–730/10 nm).
  const Spectrum& transmission_sample() const;
  // Spectrolino-like measurement noise added to a true reflectance/transmission (σ ≈ 0.001 + 0.2 %).
  Spectrum noisy_reflectance(const Spectrum& truth, std::mt19937_64& rng) const;

  // ---- determinism ----
  std::uint64_t seed() const;
  // Seed of an independent stream for a named consumer ("ls110", "spectrolino", "camera", ...).
  std::uint64_t stream_seed(std::string_view consumer) const;
  std::mt19937_64 rng_stream(std::string_view consumer) const;

  const SimClock& clock() const;
  const SceneConfig& config() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace colorlab::sim
