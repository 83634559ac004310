// The Spectrolino command set: each request's arguments checked and routed to the settings, the white
// calibration, the measurement or its results, and the answer built.
#include <array>
#include <string>

#include "colorlab/sim/scene.hpp"
#include "densitometry.hpp"
#include "spectrolino_model_impl.hpp"

namespace colorlab::sim {

namespace sp = wire::spectrolino;
using namespace spectrolino_detail;

SpectrolinoReply SpectrolinoModel::Impl::spectrolino_command(const sp::Request& r) {
  const double cmd = timing.command_s;
  const auto& a = r.args;
  auto need = [&](std::size_t n) { return a.size() == n; };
  auto ok = [&](std::uint16_t rem = 0, double s = -1) { return answer(sp::DownloadError{rem}.encode(), s < 0 ? cmd : s); };
  auto bad_len = [&] { return com_error(sp::com_err::IncorrectRecLen); };
  auto& params = settings.params;

  switch (r.opcode) {
    case sp::op::ParameterRequest:
      if (!need(0)) return bad_len();
      return answer(params.encode(), cmd);
    case sp::op::ParameterDownload: {
      if (!need(4)) return bad_len();
      std::uint16_t rem = 0;
      if (a[0] > 3 && a[0] != 8) rem |= sp::remote_err::DensityStandard;
      if (a[1] > 1) rem |= sp::remote_err::WhiteStandard;
      if (!sp::valid_illuminant(a[2])) rem |= sp::remote_err::Illuminant;
      if (a[3] > 1) rem |= sp::remote_err::Observer;
      if (!rem) {
        params.density_standard = static_cast<sp::DensityStandard>(a[0]);
        params.white_base = static_cast<sp::WhiteBase>(a[1]);
        params.illuminant = static_cast<sp::Illuminant>(a[2]);
        params.observer = static_cast<sp::Observer>(a[3]);
      }
      return ok(rem);
    }
    case sp::op::MeasControlDownload: {
      if (!need(1)) return bad_len();
      std::uint8_t c = a[0];
      if (auto baud = sp::ctt_baud(c)) {
        auto reply = ok();
        reply.baud_after = *baud;
        settings.baud = *baud;
        return reply;
      }
      switch (c) {
        case sp::ctt::HandshakeXonXoff:
        case sp::ctt::HandshakeNone:
        case sp::ctt::HandshakeHardware: settings.handshake = c; return ok();
        case sp::ctt::SpeakerOn:
        case sp::ctt::SpeakerOff: settings.speaker = c; return ok();
        case sp::ctt::ModeReflectance:
        case sp::ctt::ModeEmission: settings.mode = c; return ok();
        case sp::ctt::ModeTransmission:
          if (!config.table) return ok(sp::remote_err::NotSrOrBool);  // needs the SpectroScan T light table
          settings.mode = c;
          return ok();
        case sp::ctt::PhotometricAbsolute:
        case sp::ctt::PhotometricRelative: settings.photometric = c; return ok();
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
        m.value = settings.handshake;
      } else if (sp::ctt_baud(c)) {
        m.value = sp::baud_ctt(settings.baud).value_or(0);
      } else if (c == sp::ctt::ModeReflectance || c == sp::ctt::ModeTransmission || c == sp::ctt::ModeEmission) {
        m.value = settings.mode;
      } else if (c == sp::ctt::PhotometricAbsolute || c == sp::ctt::PhotometricRelative) {
        m.value = settings.photometric;
      } else if (c == sp::ctt::SpeakerOn || c == sp::ctt::SpeakerOff) {
        m.value = settings.speaker;
      } else {
        m.remote_errors = sp::remote_err::NotSrOrBool;
      }
      return answer(m.encode(), cmd);
    }
    case sp::op::ResetStatusDownload: {
      if (!need(3)) return bad_len();
      if (a[0] != 0x01 || a[1] != 0x04 || (a[2] != 0x01 && a[2] != 0x05)) return ok(sp::remote_err::NotSrOrBool);
      int keep_baud = settings.baud;
      std::uint8_t keep_hs = settings.handshake;
      power_cycle();
      auto reply = ok(0, timing.reset_s);
      if (a[2] == 0x05) {
        settings.baud = keep_baud;
        settings.handshake = keep_hs;
      } else if (settings.baud != keep_baud) {
        reply.baud_after = settings.baud;
      }
      return reply;
    }
    case sp::op::ExecWhiteRefToOrigDat:
      if (!need(0)) return bad_len();
      cal.set_white_reference(to_bands(scene.white_tile()), 0);
      return ok();
    case sp::op::DeviceDataRequest:
      if (!need(0)) return bad_len();
      return answer(sp::DeviceDataAnswer{"Spectrolino", sp::kDeviceNoSpectrolino, "36.77.91", config.serial,
                                         "V1.20", ""}
                        .encode(),
                    cmd);
    case sp::op::TargetIdRequest: {
      if (!need(0)) return bad_len();
      sp::TargetIdAnswer t;
      t.name = "Spectrolino";
      t.serial = static_cast<std::uint16_t>(config.serial);
      t.sw_release = 100;
      t.year = 1999;
      t.month = 6;
      t.day = 15;
      t.hour = 12;
      return answer(t.encode(), cmd);
    }
    case sp::op::WhiteReferenceRequest: {
      if (!need(1)) return bad_len();
      sp::WhiteReferenceAnswer w{static_cast<sp::Filter>(a[0]), cal.white_reference(), cal.white_reference_origin(),
                                 "WT" + std::to_string(config.serial)};
      return answer(w.encode(), cmd);
    }
    case sp::op::WhiteReferenceDownld: {
      if (!need(1 + 4 * sp::kSpectrumBands + sp::kNameLen)) return bad_len();
      sp::Reader rd(a, "white reference download");
      rd.u8("filter");
      cal.set_white_reference(rd.spectrum("white reference"), 1);
      return ok();
    }
    case sp::op::IllumTabRequest:
      if (!need(2) || a[0] != 0x00) return bad_len();
      return answer(illuminant_table(a[1], settings).encode(), cmd);
    case sp::op::IllumTabDownload: {
      if (a.size() == 3 && a[0] == 0x60) {
        unsigned k = a[1] | a[2] << 8;
        if (k < 40 || k > 250) return ok(sp::remote_err::NoValidValue);
        settings.dxx = static_cast<std::uint8_t>(k);
        return ok();
      }
      if (a.size() != 1 + 4 * sp::kSpectrumBands || a[0] != 0x08) return bad_len();
      sp::Reader rd(a, "user illuminant download");
      rd.u8("table");
      settings.user_illuminant = rd.spectrum("illuminant");
      colorimetry.forget_user_illuminant();
      return ok();
    }
    case sp::op::GetValNr:
      if (!need(1) || a[0] != 0x60) return bad_len();
      return answer(sp::ValNrAnswer{settings.dxx, 0}.encode(), cmd);
    case sp::op::DensTabRequest:
      if (!need(2) || a[0] != 0x00) return bad_len();
      return answer(density_table_answer(a[1]), cmd);
    case sp::op::DensTabDownload:
      if (!need(1 + 4 * 4 * sp::kSpectrumBands) || a[0] != 0x08) return bad_len();
      return ok();
    case sp::op::SlopeDownload: {
      if (!need(16)) return bad_len();
      sp::Reader rd(a, "slope download");
      for (auto& s : settings.slope) s = rd.f32("slope");
      return ok();
    }
    case sp::op::DensitySlopeRequest:
      if (!need(0)) return bad_len();
      return answer(sp::SlopeAnswer{settings.slope}.encode(), cmd);
    case sp::op::FloatDownload: {
      if (!need(5)) return bad_len();
      sp::Reader rd(a, "float download");
      rd.u8("type");
      settings.photometric_ref = rd.f32("value");
      return ok();
    }
    case sp::op::FloatRequest:
      if (!need(1)) return bad_len();
      return answer(sp::FloatAnswer{a[0], settings.photometric_ref}.encode(), cmd);
    case sp::op::SetMeasurementOutput:
      if (!need(2)) return bad_len();
      return ok();
    case sp::op::TargetOnOffStDownload:
      if (!need(3)) return bad_len();
      if (a[1] > 1) return ok(sp::remote_err::NotSrOrBool);
      settings.button_enabled = a[1] == 0;
      return ok();
    case sp::op::NewKeyRequest:
      if (!need(0)) return bad_len();
      return answer(sp::NewKeyAnswer{0, 0}.encode(), cmd);
    case sp::op::NewMeasureRequest: {
      if (!need(0)) return bad_len();
      auto nm = errors.new_measurement;
      errors.new_measurement = sp::NewMeasurement::None;
      return answer(sp::NewMeasureAnswer{nm}.encode(), cmd);
    }
    case sp::op::ExecMeasurement: {
      if (!need(0)) return bad_len();
      double s = 0;
      errors.last = measure(s);
      return answer(sp::ExecError{errors.last}.encode(), s);
    }
    case sp::op::ExecWhiteMeasurement: {
      if (!need(0)) return bad_len();
      double s = 0;
      errors.last = reference_measure(static_cast<std::uint8_t>(sp::RefMode::WhiteCal), s);
      return answer(sp::ExecError{errors.last}.encode(), s);
    }
    case sp::op::ExecRefMeasurement: {
      if (!need(2) || a[0] != sp::kDummy09) return bad_len();
      double s = 0;
      errors.last = reference_measure(a[1], s);
      return answer(sp::ExecError{errors.last}.encode(), s);
    }
    case sp::op::ActErrorRequest:
      if (!need(0)) return bad_len();
      return answer(sp::ActError{errors.last}.encode(), cmd);
    case sp::op::SpecParameterRequest:
    case sp::op::SpectrumRequest: {
      bool param = r.opcode == sp::op::SpecParameterRequest;
      if (!(param ? need(2) : need(1)) || a[0] != sp::kDummy09) return bad_len();
      auto type = param ? static_cast<sp::SpectrumType>(a[1]) : sp::SpectrumType::Reflectance;
      auto t = typed_spectrum(last.spectrum, type);
      std::uint8_t rv = last.spectrum ? 1 : 0;
      if (param) {
        sp::SpecParameterAnswer ans{type, t.spectrum, rv, params.filter, params.white_base, t.remote_errors};
        return answer(ans.encode(), cmd);
      }
      return answer(sp::SpectrumAnswer{type, t.spectrum, rv, t.remote_errors}.encode(), cmd);
    }
    case sp::op::CParameterRequest:
    case sp::op::CRequest: {
      bool param = r.opcode == sp::op::CParameterRequest;
      if (!(param ? need(2) : need(1)) || a[0] != sp::kDummy09) return bad_len();
      auto type = param ? static_cast<sp::ColourType>(a[1]) : sp::ColourType::XYZ;
      std::uint16_t rem = 0;
      auto c = colorimetry.colour(last, settings, type, rem).value_or(std::array<float, 3>{0, 0, 0});
      std::uint8_t rv = last.spectrum ? 1 : 0;
      if (param) {
        sp::CParameterAnswer ans{type, c, rv, params.filter, params.white_base, params.illuminant,
                                 params.observer, rem};
        return answer(ans.encode(), cmd);
      }
      return answer(sp::CAnswer{type, c, rv, rem}.encode(), cmd);
    }
    case sp::op::DensityParameterRequest:
    case sp::op::DensityRequest:
    case sp::op::DmaxRequest: {
      if (!need(1) || a[0] != sp::kDummy09) return bad_len();
      auto d = densities(last.spectrum);
      std::uint8_t rv = last.spectrum ? 1 : 0;
      if (r.opcode == sp::op::DensityParameterRequest) {
        sp::DensityParameterAnswer ans{d.status, 0, rv, params.filter, params.white_base, params.density_standard,
                                       d.remote_errors};
        return answer(ans.encode(), cmd);
      }
      if (r.opcode == sp::op::DensityRequest) return answer(sp::DensityAnswer{d.status, 0, rv, d.remote_errors}.encode(), cmd);
      return answer(sp::DmaxAnswer{d.dmax, d.dmax_nm, rv, rv, d.remote_errors}.encode(), cmd);
    }
    default: return com_error(sp::com_err::IllegalRecType);
  }
}

}  // namespace colorlab::sim
