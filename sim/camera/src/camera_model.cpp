#include "colorlab/sim/camera/camera_model.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <random>
#include <string>
#include <thread>

#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/core/error.hpp"
#include "chart_pose.hpp"
#include "floor_view.hpp"
#include "fast_random.hpp"
#include "sensitivities.hpp"

namespace colorlab::sim::camera {
namespace {

constexpr int surround_material = chart_patch_count;   // the chart's dark surround between patches
constexpr int floor_material = chart_patch_count + 1;  // cabinet floor around the chart
constexpr int material_count = chart_patch_count + 2;
constexpr double surround_reflectance = 0.05;
constexpr int noise_block_rows = 16;  // rows per independently seeded noise block
constexpr int field_node_step = 16;   // px between exact field evaluations (the field is smooth)

std::size_t lamp_index(Lamp l) { return static_cast<std::size_t>(l); }

void check_settings(const CameraSettings& s) {
  if (!(s.f_number > 0.0) || !std::isfinite(s.f_number))
    throw Error(ErrorClass::bad_parameter, "camera f-number must be > 0, got " + std::to_string(s.f_number));
  if (!(s.shutter_s > 0.0) || !std::isfinite(s.shutter_s))
    throw Error(ErrorClass::bad_parameter, "camera shutter time must be > 0 s, got " + std::to_string(s.shutter_s));
  if (s.iso < 50 || s.iso > 3200)
    throw Error(ErrorClass::bad_parameter, "camera ISO must be within 50..3200, got " + std::to_string(s.iso));
}

bool same_settings(const CameraSettings& a, const CameraSettings& b) {
  return a.f_number == b.f_number && a.shutter_s == b.shutter_s && a.iso == b.iso;
}

// Runs fn(first_row, end_row) for interleaved row blocks on `threads` threads; block i is always the same rows,
// so results do not depend on the thread count.
template <typename Fn>
void for_row_blocks(int height, int threads, Fn&& fn) {
  const int blocks = (height + noise_block_rows - 1) / noise_block_rows;
  auto worker = [&](int t, int n) {
    for (int b = t; b < blocks; b += n) fn(b, b * noise_block_rows, std::min(height, (b + 1) * noise_block_rows));
  };
  const int n = std::max(1, std::min(threads, blocks));
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(worker, t, n);
  worker(0, n);
  for (auto& th : pool) th.join();
}

}  // namespace

struct CameraModel::Impl {
  std::shared_ptr<const Scene> scene;
  CameraConfig config;
  std::uint64_t seed = 0;
  detail::Sensitivities sens;
  double px_per_mm = 0, origin_x = 0, origin_y = 0;  // chart top-left in pixels
  // The chart's geometry: set, the chart at a pose instead. With `regions` and `placement`, replaced by place_chart
  // under cache_mutex (the frame cache is built under it too); the public accessors read them under it.
  std::optional<detail::PoseGeometry> pose;
  std::optional<ChartPlacement> placement;     // the operator's, when not where the configuration put it
  std::optional<detail::FloorGeometry> floor;  // the floor view's geometry
  std::atomic<View> view{View::chart};
  std::vector<Spectrum> material_reflectance;  // material_count
  // response[lamp][material][channel]: green-normalised exposure per cd/m² of floor luminance.
  std::array<std::vector<std::array<double, 3>>, 5> response;
  std::vector<PatchRegion> regions;
  std::vector<PixelDefect> defects;
  std::vector<DustSpeck> dust;
  std::vector<float> column_offset;

  struct Precomputed {
    CameraSettings settings;
    View view = View::chart;
    std::uint64_t version = 0;
    double gain = 0;  // DN per electron
    std::vector<Lamp> lamps;
    std::vector<std::vector<float>> signal_e;                 // per lamp on, warm-up 1
    std::vector<float> base_dn;                               // black + offsets + dark signal
    std::vector<float> var0;                                  // DN² from dark shot noise and read noise
    std::vector<std::vector<std::array<double, 3>>> truth_e;  // per lamp: mean smooth electrons per patch
    double dark_e = 0;
  };
  mutable std::mutex cache_mutex;
  mutable std::shared_ptr<const Precomputed> cache;

  // Per-pixel mean and σ (DN) for the current warm-up factors: a frame then costs one fused multiply-add per
  // pixel. Rebuilt only when the lamps' warm-up has moved (rarely, and cheaply).
  struct Moments {
    std::shared_ptr<const Precomputed> pre;
    std::array<float, 5> warm{};
    std::vector<float> mean, sigma;
  };
  mutable std::mutex moments_mutex;
  mutable std::shared_ptr<const Moments> moments;
  std::shared_ptr<const Moments> moments_for(const std::shared_ptr<const Precomputed>& pre,
                                             const std::array<float, 5>& warm) const;

  // Chart millimetres of a continuous image position (pixel x covers [x, x+1)).
  std::pair<double, double> chart_mm(double u, double v) const {
    if (pose) return pose->chart_of(u, v);
    return {(u - origin_x) / px_per_mm, (v - origin_y) / px_per_mm};
  }
  // Continuous image position of a chart point.
  std::pair<double, double> image_of(double X, double Y) const {
    if (pose) return pose->image_of(X, Y);
    return {origin_x + X * px_per_mm, origin_y + Y * px_per_mm};
  }

  int material_at(int x, int y, View v) const {
    if (v == View::floor) return floor_material;  // the chart is out of the cabinet
    const auto [cx, cy] = chart_mm(x + 0.5, y + 0.5);
    if (cx < 0 || cy < 0 || cx >= chart_width_mm || cy >= chart_height_mm) return floor_material;
    const auto p = scene->chart().patch_at(cx, cy);
    return p ? *p : surround_material;
  }

  // The floor point a continuous image position sees. Beyond the floor's edges the floor view shows the walls, lit
  // as the floor where they meet it: the field stays continuous, so its interpolation between nodes never blends a
  // wall's step into the floor's edge spots.
  std::pair<double, double> floor_mm(double x, double y, View v) const {
    if (v == View::floor) {
      const auto [fx, fy] = floor->floor_of(x, y);
      return {std::clamp(fx, 0.0, cabinet_width_mm), std::clamp(fy, 0.0, cabinet_depth_mm)};
    }
    const auto [cx, cy] = chart_mm(x, y);
    return scene->chart_to_floor_mm(cx, cy);
  }

  // Continuous image position (pixel x covers [x, x+1)).
  double optics(double u, double v, double f_number, View view_now) const {
    const double dx = u - config.width / 2.0, dy = v - config.height / 2.0;
    const double r2 = (dx * dx + dy * dy) / (config.width * config.width / 4.0 + config.height * config.height / 4.0);
    const double vig = 1.0 - (0.35 / f_number) * r2;  // natural vignetting eases as the lens is stopped down
    return view_now == View::floor ? vig * floor->cos4(u, v) : vig;
  }
  double vignetting(int x, int y, double f_number, View v) const { return optics(x + 0.5, y + 0.5, f_number, v); }

  double gain_dn_per_e(const CameraSettings& s) const { return config.gain_dn_per_e_iso100 * s.iso / 100.0; }

  // Each patch's pixel rectangle for a chart geometry (nullopt: the unposed chart).
  std::vector<PatchRegion> regions_for(const std::optional<detail::PoseGeometry>& g) const;
  std::shared_ptr<const Precomputed> precomputed(const CameraSettings& settings) const;
  std::shared_ptr<const Precomputed> build(const CameraSettings& settings, std::uint64_t version) const;
  void place_defects_and_dust();
};

std::shared_ptr<const CameraModel::Impl::Precomputed> CameraModel::Impl::precomputed(const CameraSettings& s) const {
  check_settings(s);
  const std::uint64_t version = scene->state_version();
  std::lock_guard lock(cache_mutex);
  if (!cache || cache->version != version || !same_settings(cache->settings, s) || cache->view != view.load())
    cache = build(s, version);
  return cache;
}

std::shared_ptr<const CameraModel::Impl::Precomputed> CameraModel::Impl::build(const CameraSettings& s,
                                                                               std::uint64_t version) const {
  auto pre = std::make_shared<Precomputed>();
  pre->settings = s;
  pre->version = version;
  pre->view = view.load();
  const View v = pre->view;
  pre->gain = gain_dn_per_e(s);
  pre->lamps = scene->lamps_on();
  const double dimmer = scene->dimmer();
  const int W = config.width, H = config.height;
  const std::size_t n = static_cast<std::size_t>(W) * static_cast<std::size_t>(H);
  const double exposure = config.electrons_per_exposure * s.shutter_s / (s.f_number * s.f_number);
  const double g = pre->gain;
  pre->dark_e = config.dark_current_e_per_s * s.shutter_s;
  const float read_var = static_cast<float>(g * g * config.read_noise_e * config.read_noise_e +
                                            config.adc_noise_dn * config.adc_noise_dn);
  const float black = 256.0f;

  // The lamp field on a coarse node grid (it is smooth), bilinearly interpolated per pixel.
  const int nx = W / field_node_step + 2, ny = H / field_node_step + 2;
  std::vector<std::vector<double>> nodes(pre->lamps.size(), std::vector<double>(static_cast<std::size_t>(nx * ny)));
  for (std::size_t li = 0; li < pre->lamps.size(); ++li)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const auto [fx, fy] = floor_mm(i * field_node_step, j * field_node_step, v);
        nodes[li][static_cast<std::size_t>(j * nx + i)] = scene->lamp_floor_luminance(pre->lamps[li], dimmer, fx, fy);
      }

  pre->signal_e.assign(pre->lamps.size(), std::vector<float>(n));
  pre->base_dn.resize(n);
  pre->var0.resize(n);
  // Per-block partial sums for the truth, merged afterwards (blocks run on different threads).
  const int blocks = (H + noise_block_rows - 1) / noise_block_rows;
  std::vector<std::vector<std::vector<std::array<double, 4>>>> partial(
      static_cast<std::size_t>(blocks),
      std::vector<std::vector<std::array<double, 4>>>(pre->lamps.size(),
                                                      std::vector<std::array<double, 4>>(chart_patch_count * 3)));
  const std::uint64_t prnu_key = detail::splitmix64(seed ^ 0x5052'4E55ull);
  const std::uint64_t dsnu_key = detail::splitmix64(seed ^ 0x4453'4E55ull);
  const std::uint64_t dark_key = detail::splitmix64(seed ^ 0x4441'524Bull);

  for_row_blocks(H, config.threads, [&](int block, int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const int jy = y / field_node_step;
      const double ty = double(y - jy * field_node_step) / field_node_step;
      for (int x = 0; x < W; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * W + x;
        const int m = material_at(x, y, v);
        const int c = rggb_channel(x, y);
        const double vig = vignetting(x, y, s.f_number, v);
        double pixel_gain = 1.0 + config.prnu_sigma * detail::hashed_normal(prnu_key + p);
        for (const auto& d : dust) {
          const double r2 = ((x + 0.5 - d.x) * (x + 0.5 - d.x) + (y + 0.5 - d.y) * (y + 0.5 - d.y)) / (d.radius * d.radius);
          if (r2 < 1.0) pixel_gain *= 1.0 - (1.0 - d.transmission) * (1.0 - r2 * r2);  // soft-edged shadow
        }
        const int jx = x / field_node_step;
        const double tx = double(x - jx * field_node_step) / field_node_step;
        for (std::size_t li = 0; li < pre->lamps.size(); ++li) {
          const auto& nd = nodes[li];
          const std::size_t k = static_cast<std::size_t>(jy * nx + jx);
          const double field = (nd[k] * (1 - tx) + nd[k + 1] * tx) * (1 - ty) +
                               (nd[k + nx] * (1 - tx) + nd[k + nx + 1] * tx) * ty;
          const double smooth = exposure * vig * field * response[lamp_index(pre->lamps[li])][static_cast<std::size_t>(m)][static_cast<std::size_t>(c)];
          pre->signal_e[li][p] = static_cast<float>(smooth * pixel_gain);
          if (m < chart_patch_count) {
            auto& acc = partial[static_cast<std::size_t>(block)][li][static_cast<std::size_t>(m * 3 + c)];
            acc[0] += smooth;
            acc[1] += 1;
          }
        }
        const double dark = pre->dark_e * std::max(0.0, 1.0 + 0.3 * detail::hashed_normal(dark_key + p));
        const double offset = config.dsnu_sigma_dn * detail::hashed_normal(dsnu_key + p) + column_offset[static_cast<std::size_t>(x)];
        pre->base_dn[p] = static_cast<float>(black + offset + g * dark);
        pre->var0[p] = static_cast<float>(g * g * dark) + read_var;
      }
    }
  });

  // Defects are few; patch them in after the smooth pass.
  std::mt19937_64 hot_rng(detail::splitmix64(seed ^ 0x484F54ull));
  for (const auto& d : defects) {
    const std::size_t p = static_cast<std::size_t>(d.y) * W + d.x;
    if (d.kind == PixelDefect::Kind::dead) {
      for (auto& sig : pre->signal_e) sig[p] = 0.0f;
      pre->base_dn[p] = black;
      pre->var0[p] = read_var;
    } else {
      // A hot pixel: a large leakage current (grows with exposure) on top of a stuck offset.
      const double leak_e = std::uniform_real_distribution<double>(2e4, 2e5)(hot_rng) * s.shutter_s;
      const double stuck_dn = std::uniform_real_distribution<double>(300, 2500)(hot_rng);
      pre->base_dn[p] = static_cast<float>(black + stuck_dn + g * leak_e);
      pre->var0[p] = static_cast<float>(g * g * leak_e) + read_var;
    }
  }

  pre->truth_e.assign(pre->lamps.size(), std::vector<std::array<double, 3>>(chart_patch_count));
  for (std::size_t li = 0; li < pre->lamps.size(); ++li)
    for (int m = 0; m < chart_patch_count; ++m)
      for (int c = 0; c < 3; ++c) {
        double sum = 0, count = 0;
        for (const auto& blk : partial) {
          sum += blk[li][static_cast<std::size_t>(m * 3 + c)][0];
          count += blk[li][static_cast<std::size_t>(m * 3 + c)][1];
        }
        pre->truth_e[li][static_cast<std::size_t>(m)][static_cast<std::size_t>(c)] = count > 0 ? sum / count : 0.0;
      }
  return pre;
}

std::shared_ptr<const CameraModel::Impl::Moments> CameraModel::Impl::moments_for(
    const std::shared_ptr<const Precomputed>& pre, const std::array<float, 5>& warm) const {
  std::lock_guard lock(moments_mutex);
  if (moments && moments->pre == pre && moments->warm == warm) return moments;
  auto m = std::make_shared<Moments>();
  m->pre = pre;
  m->warm = warm;
  const std::size_t n = pre->base_dn.size();
  m->mean.resize(n);
  m->sigma.resize(n);
  const float g = static_cast<float>(pre->gain), g2 = g * g;
  const std::size_t lamps = pre->lamps.size();
  const int W = config.width;
  for_row_blocks(config.height, config.threads, [&](int, int y0, int y1) {
    for (std::size_t p = std::size_t(y0) * W; p < std::size_t(y1) * W; ++p) {
      float sig = 0.0f;
      for (std::size_t li = 0; li < lamps; ++li) sig += warm[li] * pre->signal_e[li][p];
      m->mean[p] = pre->base_dn[p] + g * sig + 0.5f;  // + 0.5: round to nearest on truncation
      m->sigma[p] = std::sqrt(pre->var0[p] + g2 * sig);
    }
  });
  moments = m;
  return moments;
}

std::vector<PatchRegion> CameraModel::Impl::regions_for(const std::optional<detail::PoseGeometry>& g) const {
  std::vector<PatchRegion> out;
  for (const auto& p : scene->chart().patches) {
    if (g) {
      // The largest axis-aligned rectangle centred on the patch inside its image (pixel centres at +0.5).
      const auto c = g->image_of(p.x_mm + p.size_mm / 2, p.y_mm + p.size_mm / 2);
      const double corners[4][2] = {{p.x_mm, p.y_mm}, {p.x_mm + p.size_mm, p.y_mm}, {p.x_mm + p.size_mm, p.y_mm + p.size_mm}, {p.x_mm, p.y_mm + p.size_mm}};
      double h = 1e300;
      for (int i = 0; i < 4; ++i) {
        const auto a = g->image_of(corners[i][0], corners[i][1]), b = g->image_of(corners[(i + 1) % 4][0], corners[(i + 1) % 4][1]);
        const double ex = b.first - a.first, ey = b.second - a.second, len = std::hypot(ex, ey);
        const double nx = -ey / len, ny = ex / len;
        h = std::min(h, std::abs(nx * (c.first - a.first) + ny * (c.second - a.second)) / (std::abs(nx) + std::abs(ny)));
      }
      h *= 0.95;  // the distorted edges bow a little
      const int x0 = static_cast<int>(std::ceil(c.first - h - 0.5)), x1 = static_cast<int>(std::floor(c.first + h - 0.5));
      const int y0 = static_cast<int>(std::ceil(c.second - h - 0.5)), y1 = static_cast<int>(std::floor(c.second + h - 0.5));
      out.push_back({x0, y0, std::max(1, x1 - x0 + 1), std::max(1, y1 - y0 + 1)});
      continue;
    }
    // Pixels whose centres lie inside the patch square.
    const int x0 = static_cast<int>(std::ceil(origin_x + p.x_mm * px_per_mm - 0.5));
    const int x1 = static_cast<int>(std::ceil(origin_x + (p.x_mm + p.size_mm) * px_per_mm - 0.5));
    const int y0 = static_cast<int>(std::ceil(origin_y + p.y_mm * px_per_mm - 0.5));
    const int y1 = static_cast<int>(std::ceil(origin_y + (p.y_mm + p.size_mm) * px_per_mm - 0.5));
    out.push_back({x0, y0, x1 - x0, y1 - y0});
  }
  return out;
}

void CameraModel::Impl::place_defects_and_dust() {
  std::mt19937_64 rng(detail::splitmix64(seed ^ 0x4445'4645'4354ull));
  const int W = config.width, H = config.height;
  const double pixels = double(W) * double(H);
  const auto count = [&](double fraction) {
    return fraction > 0 ? std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(fraction * pixels))) : 0;
  };
  std::uniform_int_distribution<int> ux(0, W - 1), uy(0, H - 1);
  for (std::size_t i = 0, n = count(config.hot_pixel_fraction); i < n; ++i)
    defects.push_back({ux(rng), uy(rng), PixelDefect::Kind::hot});
  for (std::size_t i = 0, n = count(config.dead_pixel_fraction); i < n; ++i)
    defects.push_back({ux(rng), uy(rng), PixelDefect::Kind::dead});

  // Dust shadows on patches away from the border, like the outliers of fig. 31(c).
  std::uniform_int_distribution<int> col(1, chart_columns - 2), row(1, chart_rows - 2);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double scale = std::max(1.0, W / 3504.0 * 8.0);
  for (int i = 0; i < config.dust_specks; ++i) {
    const int patch = col(rng) * chart_rows + row(rng);
    const auto& r = regions[static_cast<std::size_t>(patch)];
    DustSpeck d;
    d.patch = patch;
    d.radius = std::max(1.5, scale * (0.3 + 0.5 * u01(rng)));
    d.x = r.x + d.radius + u01(rng) * std::max(0.0, r.width - 2 * d.radius);
    d.y = r.y + d.radius + u01(rng) * std::max(0.0, r.height - 2 * d.radius);
    d.transmission = 0.55 + 0.3 * u01(rng);
    dust.push_back(d);
  }

  column_offset.resize(static_cast<std::size_t>(W));
  std::normal_distribution<double> n01(0.0, 1.0);
  for (auto& o : column_offset) o = static_cast<float>(config.column_offset_sigma_dn * n01(rng));
}

CameraModel::CameraModel(std::shared_ptr<const Scene> scene, CameraConfig config) : impl_(std::make_unique<Impl>()) {
  if (!scene) throw Error(ErrorClass::bad_parameter, "CameraModel needs a Scene");
  if (config.width < 64 || config.height < 64 || config.width % 2 || config.height % 2)
    throw Error(ErrorClass::bad_parameter, "camera frame must be at least 64×64 with even width and height, got " +
                                               std::to_string(config.width) + "×" + std::to_string(config.height));
  if (!(config.chart_height_fraction > 0.1 && config.chart_height_fraction <= 1.0))
    throw Error(ErrorClass::bad_parameter, "chart_height_fraction must be within (0.1, 1]");
  auto& m = *impl_;
  m.scene = std::move(scene);
  m.config = std::move(config);
  m.seed = m.config.seed ? *m.config.seed : m.scene->stream_seed("camera");
  m.sens = detail::load_sensitivities(m.config, *m.scene);
  m.px_per_mm = m.config.chart_height_fraction * m.config.height / chart_height_mm;
  if (chart_width_mm * m.px_per_mm > m.config.width)
    m.px_per_mm = m.config.width / chart_width_mm;  // portrait-ish frames: fit the width instead
  m.origin_x = (m.config.width - chart_width_mm * m.px_per_mm) / 2.0;
  m.origin_y = (m.config.height - chart_height_mm * m.px_per_mm) / 2.0;

  for (const auto& p : m.scene->chart().patches) m.material_reflectance.push_back(p.reflectance);
  m.material_reflectance.push_back(Spectrum{380.0, 350.0, {surround_reflectance, surround_reflectance}});
  m.material_reflectance.push_back(Spectrum{380.0, 350.0, {Scene::floor_reflectance(), Scene::floor_reflectance()}});
  for (Lamp l : all_lamps) {
    auto& resp = m.response[lamp_index(l)];
    resp.resize(material_count);
    for (int mat = 0; mat < material_count; ++mat) {
      const Spectrum rad = m.scene->lamp_radiance_per_cd(l, m.material_reflectance[static_cast<std::size_t>(mat)]);
      for (std::size_t c = 0; c < 3; ++c) {
        double sum = 0;
        for (std::size_t i = 0; i < rad.values.size(); ++i) sum += rad.values[i] * m.sens.rgb[c].at(rad.wavelength(i));
        resp[static_cast<std::size_t>(mat)][c] = 683.0 * sum * rad.step_nm;
      }
    }
  }
  if (m.config.pose) m.pose.emplace(*m.config.pose, m.config.width, m.config.height, m.config.chart_height_fraction);
  m.floor.emplace(m.config.width, m.config.height, m.config.floor_k1, m.config.floor_k2);
  m.regions = m.regions_for(m.pose);
  m.place_defects_and_dust();
}

CameraModel::~CameraModel() = default;

int CameraModel::width() const { return impl_->config.width; }
int CameraModel::height() const { return impl_->config.height; }
std::uint64_t CameraModel::seed() const { return impl_->seed; }
const CameraConfig& CameraModel::config() const { return impl_->config; }

RawFrame CameraModel::render(const CameraSettings& settings, std::uint64_t frame_index) const {
  RawFrame f;
  render_into(f, settings, frame_index);
  return f;
}

void CameraModel::render_into(RawFrame& out, const CameraSettings& settings, std::uint64_t frame_index) const {
  const auto pre = impl_->precomputed(settings);
  const int W = impl_->config.width, H = impl_->config.height;
  out.width = W;
  out.height = H;
  out.cfa = "RGGB";
  out.black_level = 256;
  out.white_level = 4095;
  out.frame_index = frame_index;
  out.settings = settings;
  out.pixels.resize(static_cast<std::size_t>(W) * static_cast<std::size_t>(H));

  std::array<float, 5> warm{};
  for (std::size_t li = 0; li < pre->lamps.size(); ++li)
    warm[li] = static_cast<float>(impl_->scene->output_factor(pre->lamps[li]));
  // Warm-up (and drift) is continuous; quantising it to 1e-4 keeps frames during a warm-up cheap and changes nothing visible.
  for (float& w : warm) w = std::round(w * 1e4f) / 1e4f;
  const auto mom = impl_->moments_for(pre, warm);
  const float white = static_cast<float>(out.white_level);
  const float* table = detail::normal_table().data();
  const float* mean = mom->mean.data();
  const float* sigma = mom->sigma.data();
  const std::uint64_t frame_key = detail::splitmix64(impl_->seed ^ detail::splitmix64(frame_index + 0x46524D45ull));
  std::uint16_t* dst = out.pixels.data();

  for_row_blocks(H, impl_->config.threads, [&](int block, int y0, int y1) {
    detail::Xoshiro256Plus rng(frame_key ^ (static_cast<std::uint64_t>(block) * 0xD1B54A32D192ED03ull));
    const std::size_t begin = static_cast<std::size_t>(y0) * W, end = static_cast<std::size_t>(y1) * W;
    // Four pixels per 64-bit draw (end - begin is a multiple of W, which is even; W*rows a multiple of 4 is not
    // guaranteed, so the tail is handled one by one).
    std::size_t p = begin;
    for (; p + 4 <= end; p += 4) {
      std::uint64_t bits = rng();
      for (int k = 0; k < 4; ++k, bits >>= 16) {
        const float v = std::clamp(mean[p + k] + sigma[p + k] * table[bits & 0xFFFF], 0.0f, white);
        dst[p + k] = static_cast<std::uint16_t>(v);
      }
    }
    std::uint64_t bits = rng();
    for (; p < end; ++p, bits >>= 16) dst[p] = static_cast<std::uint16_t>(std::clamp(mean[p] + sigma[p] * table[bits & 0xFFFF], 0.0f, white));
  });
}

PatchRegion CameraModel::patch_region(int patch_index) const {
  if (patch_index < 0 || patch_index >= chart_patch_count)
    throw Error(ErrorClass::bad_parameter, "patch index " + std::to_string(patch_index) + " is outside 0..139");
  std::lock_guard lock(impl_->cache_mutex);
  return impl_->regions[static_cast<std::size_t>(patch_index)];
}

std::array<double, 2> CameraModel::patch_centre_px(int patch_index) const {
  if (patch_index < 0 || patch_index >= chart_patch_count)
    throw Error(ErrorClass::bad_parameter, "patch index " + std::to_string(patch_index) + " is outside 0..139");
  const auto& p = impl_->scene->chart().patches[static_cast<std::size_t>(patch_index)];
  std::lock_guard lock(impl_->cache_mutex);
  const auto c = impl_->image_of(p.x_mm + p.size_mm / 2, p.y_mm + p.size_mm / 2);
  return {c.first - 0.5, c.second - 0.5};
}

std::array<std::array<double, 2>, 4> CameraModel::patch_grid_corners_px() const {
  const auto& ps = impl_->scene->chart().patches;
  const auto& a1 = ps.front();
  const auto& n10 = ps.back();
  const double x0 = a1.x_mm, y0 = a1.y_mm, x1 = n10.x_mm + n10.size_mm, y1 = n10.y_mm + n10.size_mm;
  std::array<std::array<double, 2>, 4> out{};
  const double pts[4][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  std::lock_guard lock(impl_->cache_mutex);
  for (std::size_t i = 0; i < 4; ++i) {
    const auto c = impl_->image_of(pts[i][0], pts[i][1]);
    out[i] = {c.first - 0.5, c.second - 0.5};
  }
  return out;
}

LensIntrinsics CameraModel::lens() const {
  std::lock_guard lock(impl_->cache_mutex);
  if (impl_->pose) return impl_->pose->intrinsics();
  const double f = impl_->px_per_mm * 1200.0;  // nominal: the chart 1.2 m away
  return {f, f, impl_->config.width / 2.0 - 0.5, impl_->config.height / 2.0 - 0.5, 0, 0};
}

std::array<double, 3> CameraModel::ground_truth(int patch_index, const CameraSettings& settings) const {
  if (patch_index < 0 || patch_index >= chart_patch_count)
    throw Error(ErrorClass::bad_parameter, "patch index " + std::to_string(patch_index) + " is outside 0..139");
  return ground_truth(settings)[static_cast<std::size_t>(patch_index)];
}

std::vector<std::array<double, 3>> CameraModel::ground_truth(const CameraSettings& settings) const {
  const auto pre = impl_->precomputed(settings);
  std::vector<std::array<double, 3>> out(chart_patch_count);
  for (int m = 0; m < chart_patch_count; ++m)
    for (std::size_t c = 0; c < 3; ++c) {
      double e = pre->dark_e;
      for (std::size_t li = 0; li < pre->lamps.size(); ++li)
        e += impl_->scene->output_factor(pre->lamps[li]) * pre->truth_e[li][static_cast<std::size_t>(m)][c];
      out[static_cast<std::size_t>(m)][c] = std::min(256.0 + pre->gain * e, 4095.0);
    }
  return out;
}

void CameraModel::place_chart(const std::optional<ChartPlacement>& placement) {
  auto& m = *impl_;
  std::optional<ChartPose> pose = m.config.pose;
  double fraction = m.config.chart_height_fraction;
  if (placement) {
    const auto& q = *placement;
    if (!(q.fill > 0.1 && q.fill <= 1.0)) throw Error(ErrorClass::bad_parameter, "a chart placement's fill must be within (0.1, 1]");
    if (!(std::abs(q.shift_x) <= 0.5 && std::abs(q.shift_y) <= 0.5))
      throw Error(ErrorClass::bad_parameter, "a chart placement's shift_x and shift_y must be within ±0.5 (fractions of the frame)");
    // The configured lens: a pose's focal length is fraction · height · distance / chart height; the square chart's
    // nominal lens (lens()) stands 1.2 m away. Its distortion (and whatever else the pose says of the lens) is kept.
    const double f = pose ? fraction * m.config.height * pose->distance_mm / chart_height_mm : m.px_per_mm * 1200.0;
    ChartPose p = pose.value_or(ChartPose{});
    p.rotation_deg = q.rotation_deg, p.tilt_deg = q.tilt_deg, p.swing_deg = q.swing_deg;
    p.shift_x = q.shift_x, p.shift_y = q.shift_y;
    p.distance_mm = f * chart_height_mm / (q.fill * m.config.height);
    pose = p;
    fraction = q.fill;
  }
  std::optional<detail::PoseGeometry> geometry;
  if (pose) geometry.emplace(*pose, m.config.width, m.config.height, fraction);  // throws for what it refuses
  std::vector<PatchRegion> regions = m.regions_for(geometry);
  std::lock_guard lock(m.cache_mutex);
  m.pose = std::move(geometry);
  m.regions = std::move(regions);
  m.placement = placement;
  m.cache.reset();
}

std::optional<ChartPlacement> CameraModel::chart_placement() const {
  std::lock_guard lock(impl_->cache_mutex);
  return impl_->placement;
}

void CameraModel::set_view(View view) { impl_->view.store(view); }
CameraModel::View CameraModel::view() const { return impl_->view.load(); }

std::array<double, 2> CameraModel::floor_point_px(double x_mm, double y_mm) const {
  const auto [u, v] = impl_->floor->image_of(x_mm, y_mm);
  return {u - 0.5, v - 0.5};
}

std::array<double, 2> CameraModel::floor_point_pinhole_px(double x_mm, double y_mm) const {
  const auto [u, v] = impl_->floor->pinhole_of(x_mm, y_mm);
  return {u - 0.5, v - 0.5};
}

LensIntrinsics CameraModel::floor_lens() const {
  const auto& f = *impl_->floor;
  return {f.focal_px(), f.focal_px(), f.cx() - 0.5, f.cy() - 0.5, f.k1(), f.k2()};
}

std::array<std::array<double, 2>, 4> CameraModel::floor_corners_px() const {
  return {floor_point_px(0, 0), floor_point_px(cabinet_width_mm, 0), floor_point_px(cabinet_width_mm, cabinet_depth_mm),
          floor_point_px(0, cabinet_depth_mm)};
}

double CameraModel::relative_illumination(double x_px, double y_px, double f_number, View view) const {
  return impl_->optics(x_px + 0.5, y_px + 0.5, f_number, view);
}

const std::vector<PixelDefect>& CameraModel::defects() const { return impl_->defects; }
const std::vector<DustSpeck>& CameraModel::dust() const { return impl_->dust; }
const std::array<Spectrum, 3>& CameraModel::sensitivities() const { return impl_->sens.rgb; }
const std::string& CameraModel::sensitivity_source() const { return impl_->sens.source; }

std::array<double, 9> CameraModel::xyz_to_camera_d65() const {
  // Least squares over the chart: camera RGB ≈ M · XYZ, both scaled so that a perfect white has G = Y = 1.
  const auto& resp = impl_->response[lamp_index(Lamp::d65)];
  const Spectrum white_refl{380.0, 350.0, {1.0, 1.0}};
  auto xyz_of = [&](const Spectrum& refl) {
    const Spectrum rad = impl_->scene->lamp_radiance_per_cd(Lamp::d65, refl);
    analysis::SpectralSet set;
    set.names = {"s"};
    set.values.resize(1, static_cast<Eigen::Index>(rad.values.size()));
    for (std::size_t i = 0; i < rad.values.size(); ++i) {
      set.wavelengths.push_back(rad.wavelength(i));
      set.values(0, static_cast<Eigen::Index>(i)) = rad.values[i];
    }
    const auto xyz = analysis::emission_to_xyz(set, analysis::Observer::cie1931_2deg, 683.0)[0];
    return Eigen::Vector3d(xyz.X, xyz.Y, xyz.Z);
  };
  const Eigen::Vector3d white_xyz = xyz_of(white_refl);
  double white_g = 0;
  {
    const Spectrum rad = impl_->scene->lamp_radiance_per_cd(Lamp::d65, white_refl);
    for (std::size_t i = 0; i < rad.values.size(); ++i) white_g += rad.values[i] * impl_->sens.rgb[1].at(rad.wavelength(i));
    white_g *= 683.0 * rad.step_nm;
  }
  Eigen::MatrixXd X(chart_patch_count, 3), C(chart_patch_count, 3);
  for (int m = 0; m < chart_patch_count; ++m) {
    X.row(m) = xyz_of(impl_->material_reflectance[static_cast<std::size_t>(m)]).transpose() / white_xyz.y();
    for (int c = 0; c < 3; ++c) C(m, c) = resp[static_cast<std::size_t>(m)][static_cast<std::size_t>(c)] / white_g;
  }
  const Eigen::Matrix3d Mt = X.colPivHouseholderQr().solve(C);  // C ≈ X · Mᵀ
  std::array<double, 9> out{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[static_cast<std::size_t>(r * 3 + c)] = Mt(c, r);
  return out;
}

std::array<double, 3> CameraModel::as_shot_neutral() const {
  const auto lamps = impl_->scene->lamps_on();
  const double dimmer = impl_->scene->dimmer();
  const auto [fx, fy] = impl_->scene->chart_to_floor_mm(chart_width_mm / 2, chart_height_mm / 2);
  const Spectrum white{380.0, 350.0, {1.0, 1.0}};
  std::array<double, 3> rgb{};
  for (Lamp l : lamps) {
    const double k = impl_->scene->lamp_floor_luminance(l, dimmer, fx, fy) * impl_->scene->output_factor(l);
    const Spectrum rad = impl_->scene->lamp_radiance_per_cd(l, white);
    for (std::size_t c = 0; c < 3; ++c) {
      double sum = 0;
      for (std::size_t i = 0; i < rad.values.size(); ++i) sum += rad.values[i] * impl_->sens.rgb[c].at(rad.wavelength(i));
      rgb[c] += k * sum;
    }
  }
  if (!(rgb[1] > 0)) return {1.0, 1.0, 1.0};  // dark cabinet: no neutral to report
  return {rgb[0] / rgb[1], 1.0, rgb[2] / rgb[1]};
}

double CameraModel::temporal_sigma_dn(double signal_dn, const CameraSettings& settings) const {
  const double g = impl_->gain_dn_per_e(settings);
  const double e = std::max(0.0, signal_dn / g);
  return std::sqrt(g * g * e + g * g * impl_->config.read_noise_e * impl_->config.read_noise_e +
                   impl_->config.adc_noise_dn * impl_->config.adc_noise_dn);
}

}  // namespace colorlab::sim::camera
