#include "colorlab/sim/spectrolino_model.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/sim/scene.hpp"

namespace colorlab::sim {

namespace sp = wire::spectrolino;
using sp::Bytes;

namespace {

constexpr int kTableMaxX = 3100;  // 0.1 mm
constexpr int kTableMaxY = 2300;
constexpr double kTile2OffsetYmm = 30.0;
constexpr double kAirReflectance = 0.002;  // head raised: stray light only

sp::Spectrum to_bands(const Spectrum& s) {
  Spectrum r = s.resampled(sp::kFirstWavelength, sp::kWavelengthStep, sp::kSpectrumBands);
  sp::Spectrum out{};
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<float>(r.values[i]);
  return out;
}

Spectrum from_bands(const sp::Spectrum& b) {
  Spectrum s{static_cast<double>(sp::kFirstWavelength), static_cast<double>(sp::kWavelengthStep),
             std::vector<double>(b.begin(), b.end())};
  return s;
}

sp::Spectrum flat(float v) {
  sp::Spectrum s{};
  s.fill(v);
  return s;
}

double axis_seconds(double d_mm, double v, double a) {
  d_mm = std::abs(d_mm);
  if (d_mm <= 0) return 0;
  if (d_mm < v * v / a) return 2.0 * std::sqrt(d_mm / a);
  return d_mm / v + v / a;
}

std::vector<double> band_grid() {
  return analysis::uniform_grid(sp::kFirstWavelength,
                                sp::kFirstWavelength + sp::kWavelengthStep * (sp::kSpectrumBands - 1),
                                sp::kWavelengthStep);
}

std::optional<std::string> colord_name(sp::Illuminant il, std::uint8_t dxx) {
  auto v = static_cast<std::uint8_t>(il);
  switch (il) {
    case sp::Illuminant::A: return "A";
    case sp::Illuminant::C: return "C";
    case sp::Illuminant::D65: return "D65";
    case sp::Illuminant::D50: return "D50";
    case sp::Illuminant::Dxx:
      if (dxx == 50 || dxx == 55 || dxx == 65 || dxx == 93) return "D" + std::to_string(dxx);
      return std::nullopt;
    default:
      if (v >= 0x18 && v <= 0x23) return "F" + std::to_string(v - 0x18 + 1);
      return std::nullopt;
  }
}

}  // namespace

struct SpectrolinoModel::Integrators {
  std::map<std::pair<int, int>, std::unique_ptr<analysis::ReflectanceIntegrator>> cache;
};

SpectrolinoModel::SpectrolinoModel(const Scene& scene, SpectrolinoConfig config, std::uint64_t seed)
    : scene_(scene), config_(std::move(config)), rng_(seed), integrators_(std::make_unique<Integrators>()) {
  if (!sp::ctt_baud(sp::baud_ctt(config_.power_on_baud).value_or(0))) {
    throw Error(ErrorClass::bad_parameter,
                "spectrolino power_on_baud " + std::to_string(config_.power_on_baud) + " is not a Spectrolino speed",
                "use 110, 150, 300, 600, 1200, 2400, 4800, 9600, 19200, 28800 or 57600");
  }
  power_cycle();
}

SpectrolinoModel::~SpectrolinoModel() = default;

void SpectrolinoModel::power_cycle() {
  baud_ = config_.power_on_baud;
  handshake_ = sp::ctt::HandshakeNone;
  mode_ = sp::ctt::ModeReflectance;
  photometric_ = sp::ctt::PhotometricAbsolute;
  params_ = sp::ParameterAnswer{};
  params_.filter = config_.filter;
  cal_ratio_.reset();
  emission_cal_ = false;
  button_enabled_ = true;
  new_meas_ = sp::NewMeasurement::None;
  last_.reset();
  last_error_ = 0;
  white_reference_ = to_bands(scene_.white_tile());
  white_reference_origin_ = 0;
  head_down_ = false;
  online_ = true;
  paper_held_ = false;
  digitizing_ = false;
  key_ack_ = false;
  special_ = 0;
  transmission_table_ = false;
  if (config_.table) x_ = y_ = 0;
}

void SpectrolinoModel::expire_calibration() {
  cal_ratio_.reset();
  emission_cal_ = false;
}

void SpectrolinoModel::set_forced_exec_error(std::optional<std::uint8_t> code, bool once) {
  forced_error_ = code;
  forced_once_ = once;
}

std::optional<std::uint8_t> SpectrolinoModel::take_forced_error() {
  auto e = forced_error_;
  if (e && forced_once_) forced_error_.reset();
  return e;
}

void SpectrolinoModel::place_head(double x_mm, double y_mm) {
  if (x_mm < 0 || y_mm < 0 || x_mm > kTableMaxX / 10.0 || y_mm > kTableMaxY / 10.0) {
    throw Error(ErrorClass::bad_parameter, "head position (" + std::to_string(x_mm) + ", " + std::to_string(y_mm) +
                                               ") mm is off the 310 x 230 mm table");
  }
  x_ = static_cast<int>(std::lround(x_mm * 10));
  y_ = static_cast<int>(std::lround(y_mm * 10));
  if (!config_.table) head_down_ = true;
}

void SpectrolinoModel::place_on_patch(int patch_index) {
  const auto& patches = scene_.chart().patches;
  if (patch_index < 0 || patch_index >= static_cast<int>(patches.size())) {
    throw Error(ErrorClass::bad_parameter, "patch index " + std::to_string(patch_index) + " is not on the chart");
  }
  const auto& p = patches[static_cast<std::size_t>(patch_index)];
  place_head(config_.chart_origin_x_mm + p.x_mm + p.size_mm / 2, config_.chart_origin_y_mm + p.y_mm + p.size_mm / 2);
}

std::pair<double, double> SpectrolinoModel::head_mm() const { return {x_ / 10.0, y_ / 10.0}; }

bool SpectrolinoModel::head_on_tile() const {
  auto [x, y] = head_mm();
  for (double ty : {config_.tile_y_mm, config_.tile_y_mm + kTile2OffsetYmm}) {
    if (std::hypot(x - config_.tile_x_mm, y - ty) <= config_.tile_radius_mm) return true;
  }
  return false;
}

double SpectrolinoModel::move_seconds(double x_mm, double y_mm) const {
  auto [x, y] = head_mm();
  return std::max(axis_seconds(x_mm - x, timing_.speed_mm_s, timing_.accel_mm_s2),
                  axis_seconds(y_mm - y, timing_.speed_mm_s, timing_.accel_mm_s2));
}

bool SpectrolinoModel::calibration_valid() const {
  if (!cal_ratio_) return false;
  if (mode_ != sp::ctt::ModeEmission && cal_mode_ != mode_) return false;
  if (cal_lifetime_s_ > 0 && scene_.clock().now() - cal_time_ > cal_lifetime_s_) return false;
  return true;
}

bool SpectrolinoModel::calibrated() const { return calibration_valid(); }

sp::Spectrum SpectrolinoModel::target_spectrum() const {
  if (mode_ == sp::ctt::ModeEmission) {
    Spectrum w = scene_.white_radiance(config_.emission_x_mm, config_.emission_y_mm);
    // Irradiance on a Lambertian white is pi x its radiance; the Spectrolino reports mW/nm/m^2.
    for (double& v : w.values) v *= std::numbers::pi * 1000.0;
    return to_bands(w);
  }
  if (mode_ == sp::ctt::ModeTransmission) return to_bands(scene_.transmission_sample());
  if (config_.table && !head_down_) return flat(static_cast<float>(kAirReflectance));
  return surface_reflectance();
}

sp::Spectrum SpectrolinoModel::surface_reflectance() const {
  if (head_on_tile()) return to_bands(scene_.white_tile());
  auto [x, y] = head_mm();
  double cx = x - config_.chart_origin_x_mm, cy = y - config_.chart_origin_y_mm;
  if (cx >= 0 && cy >= 0 && cx <= chart_width_mm && cy <= chart_height_mm) {
    const auto& chart = scene_.chart();
    if (auto i = chart.patch_at(cx, cy)) return to_bands(chart.patches[static_cast<std::size_t>(*i)].reflectance);
    return flat(static_cast<float>(config_.chart_border_reflectance));
  }
  return flat(static_cast<float>(config_.table_surface_reflectance));
}

sp::Spectrum SpectrolinoModel::true_reflectance() const { return target_spectrum(); }

sp::Spectrum SpectrolinoModel::raw_under_head() {
  sp::Spectrum truth = target_spectrum();
  if (mode_ == sp::ctt::ModeEmission) {
    std::normal_distribution<double> n(0.0, 0.002);
    double g = 1.0 + n(rng_);
    for (auto& v : truth) v = static_cast<float>(v * g);
    return truth;
  }
  return to_bands(scene_.noisy_reflectance(from_bands(truth), rng_));
}

std::uint8_t SpectrolinoModel::measure(double& seconds) {
  seconds = timing_.measure_s;
  if (auto e = take_forced_error()) return *e;
  if (mode_ == sp::ctt::ModeEmission) {
    if (!emission_cal_) return sp::exec_err::NoValidMeas;
    last_ = raw_under_head();
  } else {
    if (!calibration_valid()) return sp::exec_err::NoValidMeas;
    sp::Spectrum raw = raw_under_head();
    for (std::size_t i = 0; i < raw.size(); ++i) raw[i] *= (*cal_ratio_)[i];
    last_ = raw;
  }
  last_mode_ = mode_;
  new_meas_ = sp::NewMeasurement::Measurement;
  ++measurements_;
  return sp::exec_err::NoError;
}

std::uint8_t SpectrolinoModel::reference_measure(std::uint8_t mode, double& seconds) {
  seconds = timing_.white_cal_s;
  if (mode == static_cast<std::uint8_t>(sp::RefMode::Normal)) return measure(seconds);
  if (auto e = take_forced_error()) return *e;
  if (mode == static_cast<std::uint8_t>(sp::RefMode::EmissionCal)) {
    if (mode_ != sp::ctt::ModeEmission) return sp::exec_err::OnlyEmission;
    emission_cal_ = true;
    new_meas_ = sp::NewMeasurement::EmissionCal;
    return sp::exec_err::EmissionCalOK;
  }
  if (mode != static_cast<std::uint8_t>(sp::RefMode::WhiteCal) &&
      mode != static_cast<std::uint8_t>(sp::RefMode::WhiteCalWarn)) {
    return sp::exec_err::NoValidMeas;
  }
  sp::Spectrum ratio{};
  if (mode_ == sp::ctt::ModeTransmission) {
    ratio.fill(1.0f);  // the open light table is the 100 % reference
  } else {
    // The instrument cannot see what it is on; it only notices a white far from its tile certificate.
    if (!head_on_tile() || (config_.table && !head_down_)) return sp::exec_err::RemOverflow;
    sp::Spectrum raw = raw_under_head();
    for (std::size_t i = 0; i < raw.size(); ++i) ratio[i] = white_reference_[i] / std::max(raw[i], 1e-6f);
  }
  cal_ratio_ = ratio;
  cal_mode_ = mode_;
  cal_time_ = scene_.clock().now();
  new_meas_ = sp::NewMeasurement::WhiteCal;
  return sp::exec_err::WhiteMeasOK;
}

std::optional<std::array<float, 3>> SpectrolinoModel::colour(sp::ColourType type, std::uint16_t& rem) {
  if (!last_) {
    rem |= sp::remote_err::NoValidValue;
    return std::array<float, 3>{0, 0, 0};
  }
  analysis::Observer ob = params_.observer == sp::Observer::Deg10 ? analysis::Observer::cie1964_10deg
                                                                  : analysis::Observer::cie1931_2deg;
  analysis::Xyz xyz, white;
  if (last_mode_ == sp::ctt::ModeEmission) {
    analysis::SpectralSet s;
    s.wavelengths = band_grid();
    s.names = {"emission"};
    s.values.resize(1, sp::kSpectrumBands);
    for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) s.values(0, static_cast<Eigen::Index>(i)) = (*last_)[i] / 1000.0;
    xyz = analysis::emission_to_xyz(s, ob)[0];
    white = xyz;
  } else {
    auto key = std::make_pair(static_cast<int>(params_.illuminant), static_cast<int>(ob));
    auto& slot = integrators_->cache[key];
    if (params_.illuminant == sp::Illuminant::User) {
      if (!user_illuminant_) {
        rem |= sp::remote_err::Illuminant;
        return std::nullopt;
      }
      analysis::SpectralSet il;
      il.wavelengths = band_grid();
      il.names = {"user"};
      il.values.resize(1, sp::kSpectrumBands);
      for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) il.values(0, static_cast<Eigen::Index>(i)) = (*user_illuminant_)[i];
      slot = std::make_unique<analysis::ReflectanceIntegrator>(il, analysis::load_observer(ob), band_grid());
    } else if (!slot) {
      auto name = colord_name(params_.illuminant, dxx_);
      if (!name) {
        rem |= sp::remote_err::Illuminant;
        return std::nullopt;
      }
      slot = std::make_unique<analysis::ReflectanceIntegrator>(analysis::load_illuminant(*name),
                                                               analysis::load_observer(ob), band_grid());
    }
    Eigen::RowVectorXd r(static_cast<Eigen::Index>(sp::kSpectrumBands));
    for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) r(static_cast<Eigen::Index>(i)) = (*last_)[i];
    xyz = slot->xyz(r);
    white = slot->white();
  }
  auto f = [](double a, double b, double c) { return std::array<float, 3>{float(a), float(b), float(c)}; };
  switch (type) {
    case sp::ColourType::XYZ: return f(xyz.X, xyz.Y, xyz.Z);
    case sp::ColourType::xyY: {
      auto v = analysis::xyz_to_xyy(xyz);
      return f(v.x, v.y, v.Y);
    }
    case sp::ColourType::Lab: {
      auto v = analysis::xyz_to_lab(xyz, white);
      return f(v.L, v.a, v.b);
    }
    case sp::ColourType::LChab: {
      auto v = analysis::xyz_to_lab(xyz, white);
      double h = std::atan2(v.b, v.a) * 180.0 / std::numbers::pi;
      return f(v.L, std::hypot(v.a, v.b), h < 0 ? h + 360.0 : h);
    }
    case sp::ColourType::Luv: {
      auto v = analysis::xyz_to_luv(xyz, white);
      return f(v.L, v.u, v.v);
    }
    default: rem |= sp::remote_err::ColourSystem; return std::nullopt;
  }
}

SpectrolinoReply SpectrolinoModel::answer(const Bytes& body, double seconds) const {
  return SpectrolinoReply{sp::frame_answer(body), seconds, std::nullopt};
}

SpectrolinoReply SpectrolinoModel::com_error(std::uint8_t code) const {
  return answer(sp::ComError{code}.encode(), timing_.command_s);
}

SpectrolinoReply SpectrolinoModel::scan_error(std::uint8_t code, double seconds) const {
  return answer(sp::ScanErrorAnswer{code}.encode(), seconds);
}

SpectrolinoReply SpectrolinoModel::handle(std::string_view line) {
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
  if (line.empty() || line.front() != ';') return com_error(sp::com_err::StopButNoStart);
  Bytes body;
  try {
    body = sp::unframe_request(line);
  } catch (const Error&) {
    return com_error(sp::com_err::IllegalCharInRec);
  }
  if (body.empty()) return com_error(sp::com_err::IncorrectRecLen);
  if (body.size() == 1 && body[0] == sp::kScanRequestPrefix) return com_error(sp::com_err::IncorrectRecLen);
  sp::Request r = sp::parse_request(body);
  if (r.scan) return config_.table ? spectroscan(r) : com_error(sp::com_err::IllegalRecType);
  return spectrolino(r, line.size() + 2);
}

SpectrolinoReply SpectrolinoModel::spectrolino(const sp::Request& r, std::size_t) {
  const double cmd = timing_.command_s;
  const auto& a = r.args;
  auto need = [&](std::size_t n) { return a.size() == n; };
  auto ok = [&](std::uint16_t rem = 0, double s = -1) { return answer(sp::DownloadError{rem}.encode(), s < 0 ? cmd : s); };
  auto bad_len = [&] { return com_error(sp::com_err::IncorrectRecLen); };

  switch (r.opcode) {
    case sp::op::ParameterRequest:
      if (!need(0)) return bad_len();
      return answer(params_.encode(), cmd);
    case sp::op::ParameterDownload: {
      if (!need(4)) return bad_len();
      std::uint16_t rem = 0;
      if (a[0] > 3 && a[0] != 8) rem |= sp::remote_err::DensityStandard;
      if (a[1] > 1) rem |= sp::remote_err::WhiteStandard;
      if (!sp::valid_illuminant(a[2])) rem |= sp::remote_err::Illuminant;
      if (a[3] > 1) rem |= sp::remote_err::Observer;
      if (!rem) {
        params_.density_standard = static_cast<sp::DensityStandard>(a[0]);
        params_.white_base = static_cast<sp::WhiteBase>(a[1]);
        params_.illuminant = static_cast<sp::Illuminant>(a[2]);
        params_.observer = static_cast<sp::Observer>(a[3]);
      }
      return ok(rem);
    }
    case sp::op::MeasControlDownload: {
      if (!need(1)) return bad_len();
      std::uint8_t c = a[0];
      if (auto baud = sp::ctt_baud(c)) {
        auto reply = ok();
        reply.baud_after = *baud;
        baud_ = *baud;
        return reply;
      }
      switch (c) {
        case sp::ctt::HandshakeXonXoff:
        case sp::ctt::HandshakeNone:
        case sp::ctt::HandshakeHardware: handshake_ = c; return ok();
        case sp::ctt::SpeakerOn:
        case sp::ctt::SpeakerOff: speaker_ = c; return ok();
        case sp::ctt::ModeReflectance:
        case sp::ctt::ModeEmission: mode_ = c; return ok();
        case sp::ctt::ModeTransmission:
          if (!config_.table) return ok(sp::remote_err::NotSrOrBool);  // needs the SpectroScan T light table
          mode_ = c;
          return ok();
        case sp::ctt::PhotometricAbsolute:
        case sp::ctt::PhotometricRelative: photometric_ = c; return ok();
        case sp::ctt::CustomFilterSet:
        case sp::ctt::CustomFilterRelease: return ok();
        default: return ok(sp::remote_err::NotSrOrBool);
      }
    }
    case sp::op::MeasControlRequest: {
      if (!need(1)) return bad_len();
      std::uint8_t c = a[0];
      sp::MeasControlAnswer m{c, 0, 0};
      if (c == sp::ctt::HandshakeXonXoff || c == sp::ctt::HandshakeNone || c == sp::ctt::HandshakeHardware) {
        m.value = handshake_;
      } else if (sp::ctt_baud(c)) {
        m.value = sp::baud_ctt(baud_).value_or(0);
      } else if (c == sp::ctt::ModeReflectance || c == sp::ctt::ModeTransmission || c == sp::ctt::ModeEmission) {
        m.value = mode_;
      } else if (c == sp::ctt::PhotometricAbsolute || c == sp::ctt::PhotometricRelative) {
        m.value = photometric_;
      } else if (c == sp::ctt::SpeakerOn || c == sp::ctt::SpeakerOff) {
        m.value = speaker_;
      } else {
        m.remote_errors = sp::remote_err::NotSrOrBool;
      }
      return answer(m.encode(), cmd);
    }
    case sp::op::ResetStatusDownload: {
      if (!need(3)) return bad_len();
      if (a[0] != 0x01 || a[1] != 0x04 || (a[2] != 0x01 && a[2] != 0x05)) return ok(sp::remote_err::NotSrOrBool);
      int keep_baud = baud_;
      std::uint8_t keep_hs = handshake_;
      power_cycle();
      auto reply = ok(0, timing_.reset_s);
      if (a[2] == 0x05) {
        baud_ = keep_baud;
        handshake_ = keep_hs;
      } else if (baud_ != keep_baud) {
        reply.baud_after = baud_;
      }
      return reply;
    }
    case sp::op::ExecWhiteRefToOrigDat:
      if (!need(0)) return bad_len();
      white_reference_ = to_bands(scene_.white_tile());
      white_reference_origin_ = 0;
      return ok();
    case sp::op::DeviceDataRequest:
      if (!need(0)) return bad_len();
      return answer(sp::DeviceDataAnswer{"Spectrolino", sp::kDeviceNoSpectrolino, "36.77.91", config_.serial,
                                         "V1.20", ""}
                        .encode(),
                    cmd);
    case sp::op::TargetIdRequest: {
      if (!need(0)) return bad_len();
      sp::TargetIdAnswer t;
      t.name = "Spectrolino";
      t.serial = static_cast<std::uint16_t>(config_.serial);
      t.sw_release = 100;
      t.year = 1999;
      t.month = 6;
      t.day = 15;
      t.hour = 12;
      return answer(t.encode(), cmd);
    }
    case sp::op::WhiteReferenceRequest: {
      if (!need(1)) return bad_len();
      sp::WhiteReferenceAnswer w{static_cast<sp::Filter>(a[0]), white_reference_, white_reference_origin_,
                                 "WT" + std::to_string(config_.serial)};
      return answer(w.encode(), cmd);
    }
    case sp::op::WhiteReferenceDownld: {
      if (!need(1 + 4 * sp::kSpectrumBands + sp::kNameLen)) return bad_len();
      sp::Reader rd(a, "white reference download");
      rd.u8("filter");
      white_reference_ = rd.spectrum("white reference");
      white_reference_origin_ = 1;
      return ok();
    }
    case sp::op::IllumTabRequest: {
      if (!need(2) || a[0] != 0x00) return bad_len();
      sp::IllumTabAnswer t;
      t.illuminant = a[1];
      auto il = static_cast<sp::Illuminant>(a[1]);
      if (il == sp::Illuminant::User) {
        if (user_illuminant_) t.table = *user_illuminant_; else t.remote_errors = sp::remote_err::Illuminant;
      } else if (auto name = colord_name(il, dxx_)) {
        auto set = analysis::resample(analysis::load_illuminant(*name), band_grid(), analysis::Interpolation::linear);
        for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) t.table[i] = static_cast<float>(set.values(0, static_cast<Eigen::Index>(i)));
      } else {
        t.remote_errors = sp::remote_err::Illuminant;
      }
      return answer(t.encode(), cmd);
    }
    case sp::op::IllumTabDownload: {
      if (a.size() == 3 && a[0] == 0x60) {
        unsigned k = a[1] | a[2] << 8;
        if (k < 40 || k > 250) return ok(sp::remote_err::NoValidValue);
        dxx_ = static_cast<std::uint8_t>(k);
        return ok();
      }
      if (a.size() != 1 + 4 * sp::kSpectrumBands || a[0] != 0x08) return bad_len();
      sp::Reader rd(a, "user illuminant download");
      rd.u8("table");
      user_illuminant_ = rd.spectrum("illuminant");
      integrators_->cache.erase({static_cast<int>(sp::Illuminant::User), 0});
      integrators_->cache.erase({static_cast<int>(sp::Illuminant::User), 1});
      return ok();
    }
    case sp::op::GetValNr:
      if (!need(1) || a[0] != 0x60) return bad_len();
      return answer(sp::ValNrAnswer{dxx_, 0}.encode(), cmd);
    case sp::op::DensTabRequest: {
      if (!need(2) || a[0] != 0x00) return bad_len();
      // 3C 00 ds + 4 x 36 floats + rem2: Status-T-like bands (visual, cyan, magenta, yellow).
      sp::Writer w;
      w.u8(sp::ans::DensTabAnswer).u8(0x00).u8(a[1]);
      const double centre[4] = {555, 650, 545, 440}, width[4] = {80, 25, 25, 25};
      for (int f = 0; f < 4; ++f) {
        for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) {
          double nm = sp::kFirstWavelength + sp::kWavelengthStep * static_cast<double>(i);
          w.f32(static_cast<float>(std::exp(-0.5 * std::pow((nm - centre[f]) / width[f], 2))));
        }
      }
      w.u16(0);
      return answer(w.bytes(), cmd);
    }
    case sp::op::DensTabDownload:
      if (!need(1 + 4 * 4 * sp::kSpectrumBands) || a[0] != 0x08) return bad_len();
      return ok();
    case sp::op::SlopeDownload: {
      if (!need(16)) return bad_len();
      sp::Reader rd(a, "slope download");
      for (auto& s : slope_) s = rd.f32("slope");
      return ok();
    }
    case sp::op::DensitySlopeRequest:
      if (!need(0)) return bad_len();
      return answer(sp::SlopeAnswer{slope_}.encode(), cmd);
    case sp::op::FloatDownload: {
      if (!need(5)) return bad_len();
      sp::Reader rd(a, "float download");
      rd.u8("type");
      photometric_ref_ = rd.f32("value");
      return ok();
    }
    case sp::op::FloatRequest:
      if (!need(1)) return bad_len();
      return answer(sp::FloatAnswer{a[0], photometric_ref_}.encode(), cmd);
    case sp::op::SetMeasurementOutput:
      if (!need(2)) return bad_len();
      return ok();
    case sp::op::TargetOnOffStDownload:
      if (!need(3)) return bad_len();
      if (a[1] > 1) return ok(sp::remote_err::NotSrOrBool);
      button_enabled_ = a[1] == 0;
      return ok();
    case sp::op::NewKeyRequest:
      if (!need(0)) return bad_len();
      return answer(sp::NewKeyAnswer{0, 0}.encode(), cmd);
    case sp::op::NewMeasureRequest: {
      if (!need(0)) return bad_len();
      auto nm = new_meas_;
      new_meas_ = sp::NewMeasurement::None;
      return answer(sp::NewMeasureAnswer{nm}.encode(), cmd);
    }
    case sp::op::ExecMeasurement: {
      if (!need(0)) return bad_len();
      double s = 0;
      last_error_ = measure(s);
      return answer(sp::ExecError{last_error_}.encode(), s);
    }
    case sp::op::ExecWhiteMeasurement: {
      if (!need(0)) return bad_len();
      double s = 0;
      last_error_ = reference_measure(static_cast<std::uint8_t>(sp::RefMode::WhiteCal), s);
      return answer(sp::ExecError{last_error_}.encode(), s);
    }
    case sp::op::ExecRefMeasurement: {
      if (!need(2) || a[0] != sp::kDummy09) return bad_len();
      double s = 0;
      last_error_ = reference_measure(a[1], s);
      return answer(sp::ExecError{last_error_}.encode(), s);
    }
    case sp::op::ActErrorRequest:
      if (!need(0)) return bad_len();
      return answer(sp::ActError{last_error_}.encode(), cmd);
    case sp::op::SpecParameterRequest:
    case sp::op::SpectrumRequest: {
      bool param = r.opcode == sp::op::SpecParameterRequest;
      if (!(param ? need(2) : need(1)) || a[0] != sp::kDummy09) return bad_len();
      auto type = param ? static_cast<sp::SpectrumType>(a[1]) : sp::SpectrumType::Reflectance;
      sp::Spectrum s{};
      std::uint16_t rem = 0;
      if (last_) {
        s = *last_;
        if (type == sp::SpectrumType::Density) {
          for (auto& v : s) v = static_cast<float>(-std::log10(std::max(v, 1e-5f)));
        } else if (type != sp::SpectrumType::Reflectance) {
          rem |= sp::remote_err::Spectrum;
        }
      } else {
        rem |= sp::remote_err::NoValidValue;
      }
      std::uint8_t rv = last_ ? 1 : 0;
      if (param) {
        sp::SpecParameterAnswer ans{type, s, rv, params_.filter, params_.white_base, rem};
        return answer(ans.encode(), cmd);
      }
      return answer(sp::SpectrumAnswer{type, s, rv, rem}.encode(), cmd);
    }
    case sp::op::CParameterRequest:
    case sp::op::CRequest: {
      bool param = r.opcode == sp::op::CParameterRequest;
      if (!(param ? need(2) : need(1)) || a[0] != sp::kDummy09) return bad_len();
      auto type = param ? static_cast<sp::ColourType>(a[1]) : sp::ColourType::XYZ;
      std::uint16_t rem = 0;
      auto c = colour(type, rem).value_or(std::array<float, 3>{0, 0, 0});
      std::uint8_t rv = last_ ? 1 : 0;
      if (param) {
        sp::CParameterAnswer ans{type, c, rv, params_.filter, params_.white_base, params_.illuminant,
                                 params_.observer, rem};
        return answer(ans.encode(), cmd);
      }
      return answer(sp::CAnswer{type, c, rv, rem}.encode(), cmd);
    }
    case sp::op::DensityParameterRequest:
    case sp::op::DensityRequest:
    case sp::op::DmaxRequest: {
      if (!need(1) || a[0] != sp::kDummy09) return bad_len();
      std::array<float, 4> d{};
      std::uint16_t rem = last_ ? 0 : sp::remote_err::NoValidValue;
      float dmax = 0;
      std::uint16_t dmax_nm = 0;
      if (last_) {
        // Visual, cyan (red light), magenta (green), yellow (blue): mean reflectance over the band.
        const int lo[4] = {400, 600, 500, 400}, hi[4] = {700, 700, 590, 490};
        for (int f = 0; f < 4; ++f) {
          double sum = 0;
          int n = 0;
          for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) {
            int nm = sp::kFirstWavelength + sp::kWavelengthStep * static_cast<int>(i);
            if (nm >= lo[f] && nm <= hi[f]) {
              sum += (*last_)[i];
              ++n;
            }
          }
          d[static_cast<std::size_t>(f)] = static_cast<float>(-std::log10(std::max(sum / n, 1e-5)));
        }
        for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) {
          float v = static_cast<float>(-std::log10(std::max((*last_)[i], 1e-5f)));
          if (v > dmax) {
            dmax = v;
            dmax_nm = static_cast<std::uint16_t>(sp::kFirstWavelength + sp::kWavelengthStep * static_cast<int>(i));
          }
        }
      }
      std::uint8_t rv = last_ ? 1 : 0;
      if (r.opcode == sp::op::DensityParameterRequest) {
        sp::DensityParameterAnswer ans{d, 0, rv, params_.filter, params_.white_base, params_.density_standard, rem};
        return answer(ans.encode(), cmd);
      }
      if (r.opcode == sp::op::DensityRequest) return answer(sp::DensityAnswer{d, 0, rv, rem}.encode(), cmd);
      return answer(sp::DmaxAnswer{dmax, dmax_nm, static_cast<std::uint8_t>(last_ ? 1 : 0), rv, rem}.encode(), cmd);
    }
    default: return com_error(sp::com_err::IllegalRecType);
  }
}

SpectrolinoReply SpectrolinoModel::spectroscan(const sp::Request& r) {
  const double cmd = timing_.command_s;
  const auto& a = r.args;
  auto need = [&](std::size_t n) { return a.size() == n; };
  auto done = [&](double s) { return scan_error(sp::scan_err::NoError, s); };
  auto bad_len = [&] { return answer(sp::ScanComErrorAnswer{sp::com_err::IncorrectRecLen}.encode(), cmd); };
  auto u16at = [&](std::size_t i) { return static_cast<int>(a[i] | a[i + 1] << 8); };

  // Moves raise the head first unless "keep head down while moving" is set.
  auto move_to = [&](int nx, int ny) -> SpectrolinoReply {
    if (!online_) return scan_error(sp::scan_err::DeviceIsOffline, cmd);
    if (transmission_table_) return scan_error(sp::scan_err::NotInReflectMode, cmd);
    if (nx < 0 || ny < 0 || nx > kTableMaxX || ny > kTableMaxY) return scan_error(sp::scan_err::OutOfRange, cmd);
    double s = cmd;
    if (head_down_ && !(special_ & sp::status::SpecialHeadDownWhileMoving)) {
      s += timing_.head_s;
      head_down_ = false;
    }
    s += move_seconds(nx / 10.0, ny / 10.0);
    x_ = nx;
    y_ = ny;
    return done(s);
  };

  switch (r.opcode) {
    case sp::scan_op::MoveAbsolut:
      if (!need(5)) return bad_len();
      if (a[0] > 1) return scan_error(sp::scan_err::OutOfRange, cmd);
      return move_to(u16at(1), u16at(3));
    case sp::scan_op::MoveRelative:
      if (!need(4)) return bad_len();
      return move_to(x_ + static_cast<std::int16_t>(u16at(0)), y_ + static_cast<std::int16_t>(u16at(2)));
    case sp::scan_op::MoveHome:
      if (!need(0)) return bad_len();
      return move_to(0, 0);
    case sp::scan_op::MoveUp:
    case sp::scan_op::MoveDown: {
      if (!need(0)) return bad_len();
      if (!online_) return scan_error(sp::scan_err::DeviceIsOffline, cmd);
      bool down = r.opcode == sp::scan_op::MoveDown;
      double s = cmd + (head_down_ != down ? timing_.head_s : 0);
      head_down_ = down;
      return done(s);
    }
    case sp::scan_op::OutputActualPosition:
      if (!need(1)) return bad_len();
      return answer(sp::PositionAnswer{static_cast<sp::ScanRef>(a[0]), 0, static_cast<std::uint16_t>(x_),
                                       static_cast<std::uint16_t>(y_), static_cast<std::uint8_t>(head_down_ ? 1 : 0)}
                        .encode(),
                    cmd);
    case sp::scan_op::OutputDigitizedValues:
      if (!need(1)) return bad_len();
      if (!digitizing_) return scan_error(sp::scan_err::NoAccess, cmd);
      return answer(sp::PositionAnswer{static_cast<sp::ScanRef>(a[0]), 0, static_cast<std::uint16_t>(x_),
                                       static_cast<std::uint16_t>(y_), static_cast<std::uint8_t>(head_down_ ? 1 : 0)}
                        .encode(),
                    cmd);
    case sp::scan_op::MoveToWhiteRefPos: {
      if (!need(1)) return bad_len();
      if (a[0] > 1) return scan_error(sp::scan_err::OutOfRange, cmd);
      double ty = config_.tile_y_mm + (a[0] == 1 ? kTile2OffsetYmm : 0.0);
      return move_to(static_cast<int>(std::lround(config_.tile_x_mm * 10)), static_cast<int>(std::lround(ty * 10)));
    }
    case sp::scan_op::MoveAndMeasure: {
      if (!need(4)) return bad_len();
      auto moved = move_to(u16at(0), u16at(2));
      auto head = sp::ScanErrorAnswer::decode(sp::unframe_answer(moved.bytes));
      if (head.error != sp::scan_err::NoError) return moved;
      double s = moved.device_seconds + timing_.head_s;
      head_down_ = true;
      double ms = 0;
      std::uint8_t e = measure(ms);
      last_error_ = e;
      s += ms + timing_.head_s;
      head_down_ = false;
      if (e != sp::exec_err::NoError) return scan_error(sp::scan_err::MeasError, s);
      new_meas_ = sp::NewMeasurement::None;  // the answer carries it
      return answer(sp::SpectrumAnswer{sp::SpectrumType::Reflectance, *last_, 1, 0}.encode(), s);
    }
    case sp::scan_op::InitializeDevice:
      if (!need(0)) return bad_len();
      x_ = y_ = 0;
      head_down_ = false;
      online_ = true;
      paper_held_ = false;
      digitizing_ = false;
      return done(timing_.init_s);
    case sp::scan_op::ScanSpectrolino:
      if (!need(0)) return bad_len();
      return done(0.5);
    case sp::scan_op::InitMotorPosition: {
      if (!need(0)) return bad_len();
      double s = move_seconds(0, 0) + timing_.head_s;
      x_ = y_ = 0;
      head_down_ = false;
      return done(s);
    }
    case sp::scan_op::SetTableMode:
      if (!need(1)) return bad_len();
      if (a[0] > 1) return scan_error(sp::scan_err::OutOfRange, cmd);
      transmission_table_ = a[0] == 1;
      mode_ = transmission_table_ ? sp::ctt::ModeTransmission : sp::ctt::ModeReflectance;
      return done(1.0);
    case sp::scan_op::SetLightLevel:
      if (!need(1)) return bad_len();
      if (!transmission_table_) return scan_error(sp::scan_err::NotInTransmMode, cmd);
      if (a[0] > 2) return scan_error(sp::scan_err::OutOfRange, cmd);
      light_level_ = a[0];
      return done(cmd);
    case sp::scan_op::SetTransmStandbyPos:
      if (!need(5)) return bad_len();
      if (!transmission_table_) return scan_error(sp::scan_err::NotInTransmMode, cmd);
      if (u16at(1) > kTableMaxX || u16at(3) > kTableMaxY) return scan_error(sp::scan_err::OutOfRange, cmd);
      return done(cmd);
    case sp::scan_op::SetDeviceOnline:
    case sp::scan_op::SetDeviceOffline:
      if (!need(0)) return bad_len();
      online_ = r.opcode == sp::scan_op::SetDeviceOnline;
      return done(cmd);
    case sp::scan_op::HoldPaper:
    case sp::scan_op::ReleasePaper:
      if (!need(0)) return bad_len();
      paper_held_ = r.opcode == sp::scan_op::HoldPaper;
      return done(0.2);
    case sp::scan_op::SetDigitizingMode:
      if (!need(0)) return bad_len();
      digitizing_ = true;
      return done(cmd);
    case sp::scan_op::SetKeyAcknowlge:
    case sp::scan_op::ResetKeyAcknowlge:
      if (!need(0)) return bad_len();
      key_ack_ = r.opcode == sp::scan_op::SetKeyAcknowlge;
      return done(cmd);
    case sp::scan_op::OutputActualKey:
    case sp::scan_op::OutputLastKey:
      if (!need(0)) return bad_len();
      return answer(sp::KeyAnswer{0, 0}.encode(), cmd);
    case sp::scan_op::OutputStatus: {
      if (!need(0)) return bad_len();
      std::uint8_t bits = 0;
      if (online_) bits |= sp::status::Online;
      if (digitizing_) bits |= sp::status::Digitizing;
      if (key_ack_) bits |= sp::status::KeyAck;
      if (paper_held_) bits |= sp::status::PaperHeld;
      return answer(sp::StatusAnswer{bits}.encode(), cmd);
    }
    case sp::scan_op::ClearStatus:
      if (!need(1)) return bad_len();
      if (a[0] & sp::status::Digitizing) digitizing_ = false;
      if (a[0] & sp::status::KeyAck) key_ack_ = false;
      return done(cmd);
    case sp::scan_op::SetSpecialStatus:
    case sp::scan_op::ClearSpecialStatus:
      if (!need(1)) return bad_len();
      if (r.opcode == sp::scan_op::SetSpecialStatus) special_ |= a[0]; else special_ &= static_cast<std::uint8_t>(~a[0]);
      return done(cmd);
    case sp::scan_op::OutputSpecialStatus: {
      if (!need(0)) return bad_len();
      std::uint8_t bits = special_;
      if (transmission_table_) bits |= sp::status::SpecialTransmission;
      return answer(sp::StatusAnswer{bits}.encode(), cmd);
    }
    case sp::scan_op::ChangeBaudRate: {
      if (!need(1)) return bad_len();
      auto baud = sp::scan_bt_baud(a[0]);
      if (!baud) return scan_error(sp::scan_err::OutOfRange, cmd);
      auto reply = done(cmd);
      reply.baud_after = *baud;
      baud_ = *baud;
      return reply;
    }
    case sp::scan_op::ChangeHandshake:
      if (!need(1)) return bad_len();
      if (a[0] > 2) return scan_error(sp::scan_err::OutOfRange, cmd);
      handshake_ = a[0] == 2 ? sp::ctt::HandshakeHardware : a[0] == 1 ? sp::ctt::HandshakeXonXoff : sp::ctt::HandshakeNone;
      return done(cmd);
    case sp::scan_op::OutputType:
      if (!need(0)) return bad_len();
      return answer(sp::TypeAnswer{"SpectroScanT"}.encode(), cmd);
    case sp::scan_op::OutputSerialNumber:
      if (!need(0)) return bad_len();
      return answer(sp::SerialNumberAnswer{config_.table_serial}.encode(), cmd);
    case sp::scan_op::OutputArticleNumber:
      if (!need(0)) return bad_len();
      return answer(sp::ArticleNumberAnswer{"36.67.50"}.encode(), cmd);
    case sp::scan_op::OutputProductionDate:
      if (!need(0)) return bad_len();
      return answer(sp::ProductionDateAnswer{20, 9, 2000}.encode(), cmd);
    case sp::scan_op::OutputSoftwareVersion:
      if (!need(0)) return bad_len();
      return answer(sp::SoftwareVersionAnswer{"V2.05"}.encode(), cmd);
    default: return scan_error(sp::scan_err::NoCommand, cmd);
  }
}

std::optional<sp::Spectrum> SpectrolinoModel::last_spectrum() const { return last_; }

}  // namespace colorlab::sim
