#include "colorimetry.hpp"

#include <cmath>
#include <numbers>

#include "colorlab/analysis/colorimetry.hpp"

namespace colorlab::sim::spectrolino_detail {

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

sp::IllumTabAnswer illuminant_table(std::uint8_t illuminant, const DeviceSettings& settings) {
  sp::IllumTabAnswer t;
  t.illuminant = illuminant;
  auto il = static_cast<sp::Illuminant>(illuminant);
  if (il == sp::Illuminant::User) {
    if (settings.user_illuminant) t.table = *settings.user_illuminant;
    else t.remote_errors = sp::remote_err::Illuminant;
  } else if (auto name = colord_name(il, settings.dxx)) {
    auto set = analysis::resample(analysis::load_illuminant(*name), band_grid(), analysis::Interpolation::linear);
    for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) t.table[i] = static_cast<float>(set.values(0, static_cast<Eigen::Index>(i)));
  } else {
    t.remote_errors = sp::remote_err::Illuminant;
  }
  return t;
}

Colorimetry::Colorimetry() = default;
Colorimetry::~Colorimetry() = default;

void Colorimetry::forget_user_illuminant() {
  integrators_.erase({static_cast<int>(sp::Illuminant::User), 0});
  integrators_.erase({static_cast<int>(sp::Illuminant::User), 1});
}

std::optional<std::array<float, 3>> Colorimetry::colour(const LastMeasurement& last, const DeviceSettings& settings,
                                                        sp::ColourType type, std::uint16_t& rem) {
  if (!last.spectrum) {
    rem |= sp::remote_err::NoValidValue;
    return std::array<float, 3>{0, 0, 0};
  }
  const sp::Spectrum& spectrum = *last.spectrum;
  const auto& params = settings.params;
  analysis::Observer ob = params.observer == sp::Observer::Deg10 ? analysis::Observer::cie1964_10deg
                                                                 : analysis::Observer::cie1931_2deg;
  analysis::Xyz xyz, white;
  if (last.mode == sp::ctt::ModeEmission) {
    analysis::SpectralSet s;
    s.wavelengths = band_grid();
    s.names = {"emission"};
    s.values.resize(1, sp::kSpectrumBands);
    for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) s.values(0, static_cast<Eigen::Index>(i)) = spectrum[i] / 1000.0;
    xyz = analysis::emission_to_xyz(s, ob)[0];
    white = xyz;
  } else {
    auto key = std::make_pair(static_cast<int>(params.illuminant), static_cast<int>(ob));
    auto& slot = integrators_[key];
    if (params.illuminant == sp::Illuminant::User) {
      if (!settings.user_illuminant) {
        rem |= sp::remote_err::Illuminant;
        return std::nullopt;
      }
      analysis::SpectralSet il;
      il.wavelengths = band_grid();
      il.names = {"user"};
      il.values.resize(1, sp::kSpectrumBands);
      for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) il.values(0, static_cast<Eigen::Index>(i)) = (*settings.user_illuminant)[i];
      slot = std::make_unique<analysis::ReflectanceIntegrator>(il, analysis::load_observer(ob), band_grid());
    } else if (!slot) {
      auto name = colord_name(params.illuminant, settings.dxx);
      if (!name) {
        rem |= sp::remote_err::Illuminant;
        return std::nullopt;
      }
      slot = std::make_unique<analysis::ReflectanceIntegrator>(analysis::load_illuminant(*name),
                                                               analysis::load_observer(ob), band_grid());
    }
    Eigen::RowVectorXd r(static_cast<Eigen::Index>(sp::kSpectrumBands));
    for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) r(static_cast<Eigen::Index>(i)) = spectrum[i];
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

}  // namespace colorlab::sim::spectrolino_detail
