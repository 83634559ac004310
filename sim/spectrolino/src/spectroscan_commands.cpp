// The SpectroScan T command set (D0 ...): each request's arguments checked and routed to the table's
// kinematics, or for MoveAndMeasure to the table and the measurement, and the D1 answer built.
#include <cmath>

#include "spectrolino_model_impl.hpp"

namespace colorlab::sim {

namespace sp = wire::spectrolino;
using namespace spectrolino_detail;

SpectrolinoReply SpectrolinoModel::Impl::spectroscan_command(const sp::Request& r) {
  const double cmd = timing.command_s;
  const auto& a = r.args;
  auto need = [&](std::size_t n) { return a.size() == n; };
  auto done = [&](double s) { return scan_error(sp::scan_err::NoError, s); };
  auto result = [&](TableResult t) { return scan_error(t.scan_error, t.seconds); };
  auto bad_len = [&] { return answer(sp::ScanComErrorAnswer{sp::com_err::IncorrectRecLen}.encode(), cmd); };
  auto u16at = [&](std::size_t i) { return static_cast<int>(a[i] | a[i + 1] << 8); };
  auto position = [&] {
    return answer(sp::PositionAnswer{static_cast<sp::ScanRef>(a[0]), 0, static_cast<std::uint16_t>(table.x),
                                     static_cast<std::uint16_t>(table.y),
                                     static_cast<std::uint8_t>(table.head_down ? 1 : 0)}
                      .encode(),
                  cmd);
  };

  switch (r.opcode) {
    case sp::scan_op::MoveAbsolut:
      if (!need(5)) return bad_len();
      if (a[0] > 1) return scan_error(sp::scan_err::OutOfRange, cmd);
      return result(table.move_to(u16at(1), u16at(3), timing));
    case sp::scan_op::MoveRelative:
      if (!need(4)) return bad_len();
      return result(table.move_to(table.x + static_cast<std::int16_t>(u16at(0)),
                                  table.y + static_cast<std::int16_t>(u16at(2)), timing));
    case sp::scan_op::MoveHome:
      if (!need(0)) return bad_len();
      return result(table.move_to(0, 0, timing));
    case sp::scan_op::MoveUp:
    case sp::scan_op::MoveDown:
      if (!need(0)) return bad_len();
      return result(table.set_head(r.opcode == sp::scan_op::MoveDown, timing));
    case sp::scan_op::OutputActualPosition:
      if (!need(1)) return bad_len();
      return position();
    case sp::scan_op::OutputDigitizedValues:
      if (!need(1)) return bad_len();
      if (!table.digitizing) return scan_error(sp::scan_err::NoAccess, cmd);
      return position();
    case sp::scan_op::MoveToWhiteRefPos: {
      if (!need(1)) return bad_len();
      if (a[0] > 1) return scan_error(sp::scan_err::OutOfRange, cmd);
      double ty = config.tile_y_mm + (a[0] == 1 ? kTile2OffsetYmm : 0.0);
      return result(table.move_to(static_cast<int>(std::lround(config.tile_x_mm * 10)),
                                  static_cast<int>(std::lround(ty * 10)), timing));
    }
    case sp::scan_op::MoveAndMeasure: {
      if (!need(4)) return bad_len();
      auto moved = table.move_to(u16at(0), u16at(2), timing);
      if (moved.scan_error != sp::scan_err::NoError) return result(moved);
      double s = moved.seconds + timing.head_s;
      table.head_down = true;
      double ms = 0;
      std::uint8_t e = measure(ms);
      errors.last = e;
      s += ms + timing.head_s;
      table.head_down = false;
      if (e != sp::exec_err::NoError) return scan_error(sp::scan_err::MeasError, s);
      errors.new_measurement = sp::NewMeasurement::None;  // the answer carries it
      return answer(sp::SpectrumAnswer{sp::SpectrumType::Reflectance, *last.spectrum, 1, 0}.encode(), s);
    }
    case sp::scan_op::InitializeDevice:
      if (!need(0)) return bad_len();
      return done(table.initialize(timing));
    case sp::scan_op::ScanSpectrolino:
      if (!need(0)) return bad_len();
      return done(0.5);
    case sp::scan_op::InitMotorPosition:
      if (!need(0)) return bad_len();
      return done(table.init_motor(timing));
    case sp::scan_op::SetTableMode:
      if (!need(1)) return bad_len();
      if (a[0] > 1) return scan_error(sp::scan_err::OutOfRange, cmd);
      table.transmission = a[0] == 1;
      settings.mode = table.transmission ? sp::ctt::ModeTransmission : sp::ctt::ModeReflectance;
      return done(1.0);
    case sp::scan_op::SetLightLevel:
      if (!need(1)) return bad_len();
      return scan_error(table.set_light_level(a[0]), cmd);
    case sp::scan_op::SetTransmStandbyPos:
      if (!need(5)) return bad_len();
      return scan_error(table.check_standby_position(u16at(1), u16at(3)), cmd);
    case sp::scan_op::SetDeviceOnline:
    case sp::scan_op::SetDeviceOffline:
      if (!need(0)) return bad_len();
      table.online = r.opcode == sp::scan_op::SetDeviceOnline;
      return done(cmd);
    case sp::scan_op::HoldPaper:
    case sp::scan_op::ReleasePaper:
      if (!need(0)) return bad_len();
      table.paper_held = r.opcode == sp::scan_op::HoldPaper;
      return done(0.2);
    case sp::scan_op::SetDigitizingMode:
      if (!need(0)) return bad_len();
      table.digitizing = true;
      return done(cmd);
    case sp::scan_op::SetKeyAcknowlge:
    case sp::scan_op::ResetKeyAcknowlge:
      if (!need(0)) return bad_len();
      table.key_ack = r.opcode == sp::scan_op::SetKeyAcknowlge;
      return done(cmd);
    case sp::scan_op::OutputActualKey:
    case sp::scan_op::OutputLastKey:
      if (!need(0)) return bad_len();
      return answer(sp::KeyAnswer{0, 0}.encode(), cmd);
    case sp::scan_op::OutputStatus:
      if (!need(0)) return bad_len();
      return answer(sp::StatusAnswer{table.status()}.encode(), cmd);
    case sp::scan_op::ClearStatus:
      if (!need(1)) return bad_len();
      table.clear_status(a[0]);
      return done(cmd);
    case sp::scan_op::SetSpecialStatus:
    case sp::scan_op::ClearSpecialStatus:
      if (!need(1)) return bad_len();
      if (r.opcode == sp::scan_op::SetSpecialStatus) table.special |= a[0];
      else table.special &= static_cast<std::uint8_t>(~a[0]);
      return done(cmd);
    case sp::scan_op::OutputSpecialStatus:
      if (!need(0)) return bad_len();
      return answer(sp::StatusAnswer{table.special_status()}.encode(), cmd);
    case sp::scan_op::ChangeBaudRate: {
      if (!need(1)) return bad_len();
      auto baud = sp::scan_bt_baud(a[0]);
      if (!baud) return scan_error(sp::scan_err::OutOfRange, cmd);
      auto reply = done(cmd);
      reply.baud_after = *baud;
      settings.baud = *baud;
      return reply;
    }
    case sp::scan_op::ChangeHandshake:
      if (!need(1)) return bad_len();
      if (a[0] > 2) return scan_error(sp::scan_err::OutOfRange, cmd);
      settings.handshake = a[0] == 2   ? sp::ctt::HandshakeHardware
                           : a[0] == 1 ? sp::ctt::HandshakeXonXoff
                                       : sp::ctt::HandshakeNone;
      return done(cmd);
    case sp::scan_op::OutputType:
      if (!need(0)) return bad_len();
      return answer(sp::TypeAnswer{"SpectroScanT"}.encode(), cmd);
    case sp::scan_op::OutputSerialNumber:
      if (!need(0)) return bad_len();
      return answer(sp::SerialNumberAnswer{config.table_serial}.encode(), cmd);
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

}  // namespace colorlab::sim
