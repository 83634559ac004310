#include <cstdio>

#include "colorlab/wire/spectrolino_protocol.hpp"

namespace colorlab::wire::spectrolino {

namespace {

std::string hex2(std::uint8_t v) {
  char buf[4];
  std::snprintf(buf, sizeof buf, "%02X", v);
  return buf;
}

Bytes with(std::initializer_list<std::uint8_t> b) { return Bytes(b); }

// Explains an unexpected answer, naming the error it carries when it is an error answer.
[[noreturn]] void wrong_answer(std::span<const std::uint8_t> body, std::string_view expected) {
  std::string got = body.empty() ? std::string("an empty body") : to_hex(body);
  std::string msg = "expected Spectrolino answer " + std::string(expected) + ", got " + got;
  ErrorClass cls = ErrorClass::protocol_error;
  std::string code;
  if (body.size() == 2 && body[0] == ans::ComError) {
    auto info = describe_com_error(body[1]);
    msg += " (COM error " + hex2(body[1]) + ": " + std::string(info.meaning) + ")";
    cls = info.cls;
    code = "spectrolino-com:" + hex2(body[1]);
  } else if (body.size() == 2 && body[0] == ans::ExecError) {
    auto info = describe_exec_error(body[1]);
    msg += " (error " + hex2(body[1]) + ": " + std::string(info.meaning) + ")";
    cls = info.cls == ErrorClass::internal ? ErrorClass::protocol_error : info.cls;
    code = "spectrolino:" + hex2(body[1]);
  } else if (body.size() == 3 && body[0] == kScanAnswerPrefix && body[1] == scan_ans::ErrorAnswer) {
    auto info = describe_scan_error(body[2]);
    msg += " (SpectroScan error " + hex2(body[2]) + ": " + std::string(info.meaning) + ")";
    cls = info.cls == ErrorClass::internal ? ErrorClass::protocol_error : info.cls;
    code = "spectroscan:" + hex2(body[2]);
  } else if (body.size() == 3 && body[0] == kScanAnswerPrefix && body[1] == scan_ans::ComErrorAnswer) {
    auto info = describe_com_error(body[2]);
    msg += " (SpectroScan COM error " + hex2(body[2]) + ": " + std::string(info.meaning) + ")";
    cls = info.cls;
    code = "spectroscan-com:" + hex2(body[2]);
  }
  ErrorInfo e;
  e.cls = cls;
  e.message = std::move(msg);
  e.device_code = std::move(code);
  throw Error(std::move(e));
}

// Opens a reader positioned after the answer code, or throws naming what came instead.
Reader open(std::span<const std::uint8_t> body, std::uint8_t code, std::string_view name) {
  if (body.empty() || body[0] != code) wrong_answer(body, hex2(code) + " " + std::string(name));
  Reader r(body, "Spectrolino answer " + hex2(code) + " " + std::string(name));
  r.u8("answer code");
  return r;
}

Reader open_scan(std::span<const std::uint8_t> body, std::uint8_t code, std::string_view name) {
  if (body.size() < 2 || body[0] != kScanAnswerPrefix || body[1] != code) {
    wrong_answer(body, "D1 " + hex2(code) + " " + std::string(name));
  }
  Reader r(body, "SpectroScan answer D1 " + hex2(code) + " " + std::string(name));
  r.u8("prefix");
  r.u8("answer code");
  return r;
}

Writer answer(std::uint8_t code) {
  Writer w;
  w.u8(code);
  return w;
}

Writer scan_answer(std::uint8_t code) {
  Writer w;
  w.u8(kScanAnswerPrefix).u8(code);
  return w;
}

template <class E>
std::uint8_t u8_of(E e) {
  return static_cast<std::uint8_t>(e);
}

}  // namespace

// ---------------------------------------------------------------- requests

namespace req {
Bytes parameter_request() { return with({op::ParameterRequest}); }
Bytes parameter_download(DensityStandard ds, WhiteBase wb, Illuminant il, Observer ob) {
  return with({op::ParameterDownload, u8_of(ds), u8_of(wb), u8_of(il), u8_of(ob)});
}
Bytes meas_control_download(std::uint8_t c) { return with({op::MeasControlDownload, c}); }
Bytes meas_control_request(std::uint8_t c) { return with({op::MeasControlRequest, c}); }
Bytes reset_status(std::uint8_t sm) { return with({op::ResetStatusDownload, 0x01, 0x04, sm}); }
Bytes white_ref_to_orig() { return with({op::ExecWhiteRefToOrigDat}); }
Bytes device_data_request() { return with({op::DeviceDataRequest}); }
Bytes target_id_request() { return with({op::TargetIdRequest}); }
Bytes white_reference_request(Filter f) { return with({op::WhiteReferenceRequest, u8_of(f)}); }
Bytes white_reference_download(Filter f, const Spectrum& s, std::string_view name) {
  Writer w;
  w.u8(op::WhiteReferenceDownld).u8(u8_of(f)).floats(s).str(name, kNameLen);
  return w.take();
}
Bytes illum_tab_request(Illuminant il) { return with({op::IllumTabRequest, 0x00, u8_of(il)}); }
Bytes illum_tab_download(const Spectrum& s) {
  Writer w;
  w.u8(op::IllumTabDownload).u8(0x08).floats(s);
  return w.take();
}
Bytes dxx_temperature_request() { return with({op::GetValNr, 0x60}); }
Bytes dxx_temperature_set(std::uint16_t k) {
  Writer w;
  w.u8(op::IllumTabDownload).u8(0x60).u16(k);
  return w.take();
}
Bytes float_request(std::uint8_t type) { return with({op::FloatRequest, type}); }
Bytes float_download(std::uint8_t type, float v) {
  Writer w;
  w.u8(op::FloatDownload).u8(type).f32(v);
  return w.take();
}
Bytes set_measurement_output(std::uint8_t type, std::uint8_t mask) {
  return with({op::SetMeasurementOutput, type, mask});
}
Bytes exec_ref_measurement(RefMode mode) { return with({op::ExecRefMeasurement, kDummy09, u8_of(mode)}); }
Bytes exec_white_measurement() { return with({op::ExecWhiteMeasurement}); }
Bytes exec_measurement() { return with({op::ExecMeasurement}); }
Bytes new_measure_request() { return with({op::NewMeasureRequest}); }
Bytes new_key_request() { return with({op::NewKeyRequest}); }
Bytes target_on_off(bool deactivated) {
  return with({op::TargetOnOffStDownload, 0x00, static_cast<std::uint8_t>(deactivated ? 1 : 0), 0x00});
}
Bytes spec_parameter_request(SpectrumType t) { return with({op::SpecParameterRequest, kDummy09, u8_of(t)}); }
Bytes spectrum_request() { return with({op::SpectrumRequest, kDummy09}); }
Bytes c_parameter_request(ColourType t) { return with({op::CParameterRequest, kDummy09, u8_of(t)}); }
Bytes c_request() { return with({op::CRequest, kDummy09}); }
Bytes density_parameter_request() { return with({op::DensityParameterRequest, kDummy09}); }
Bytes density_request() { return with({op::DensityRequest, kDummy09}); }
Bytes dmax_request() { return with({op::DmaxRequest, kDummy09}); }
Bytes act_error_request() { return with({op::ActErrorRequest}); }

Bytes scan(std::uint8_t scan_opcode, std::span<const std::uint8_t> args) {
  Writer w;
  w.u8(kScanRequestPrefix).u8(scan_opcode).raw(args);
  return w.take();
}
Bytes move_absolute(ScanRef ref, std::uint16_t x, std::uint16_t y) {
  Writer w;
  w.u8(kScanRequestPrefix).u8(scan_op::MoveAbsolut).u8(u8_of(ref)).u16(x).u16(y);
  return w.take();
}
Bytes move_relative(std::int16_t dx, std::int16_t dy) {
  Writer w;
  w.u8(kScanRequestPrefix)
      .u8(scan_op::MoveRelative)
      .u16(static_cast<std::uint16_t>(dx))
      .u16(static_cast<std::uint16_t>(dy));
  return w.take();
}
Bytes move_home() { return scan(scan_op::MoveHome); }
Bytes move_up() { return scan(scan_op::MoveUp); }
Bytes move_down() { return scan(scan_op::MoveDown); }
Bytes output_position(ScanRef ref) {
  std::uint8_t a[] = {u8_of(ref)};
  return scan(scan_op::OutputActualPosition, a);
}
Bytes move_to_white(std::uint8_t tile) {
  std::uint8_t a[] = {tile};
  return scan(scan_op::MoveToWhiteRefPos, a);
}
Bytes move_and_measure(std::uint16_t x, std::uint16_t y) {
  Writer w;
  w.u8(kScanRequestPrefix).u8(scan_op::MoveAndMeasure).u16(x).u16(y);
  return w.take();
}
Bytes initialize_device() { return scan(scan_op::InitializeDevice); }
Bytes scan_spectrolino() { return scan(scan_op::ScanSpectrolino); }
Bytes init_motor_position() { return scan(scan_op::InitMotorPosition); }
Bytes set_table_mode(TableMode m) {
  std::uint8_t a[] = {u8_of(m)};
  return scan(scan_op::SetTableMode, a);
}
Bytes set_light_level(std::uint8_t level) {
  std::uint8_t a[] = {level};
  return scan(scan_op::SetLightLevel, a);
}
Bytes set_online() { return scan(scan_op::SetDeviceOnline); }
Bytes set_offline() { return scan(scan_op::SetDeviceOffline); }
Bytes hold_paper() { return scan(scan_op::HoldPaper); }
Bytes release_paper() { return scan(scan_op::ReleasePaper); }
Bytes change_baud(std::uint8_t bt) {
  std::uint8_t a[] = {bt};
  return scan(scan_op::ChangeBaudRate, a);
}
Bytes change_handshake(ScanHandshake hs) {
  std::uint8_t a[] = {u8_of(hs)};
  return scan(scan_op::ChangeHandshake, a);
}
Bytes output_status() { return scan(scan_op::OutputStatus); }
Bytes clear_status(std::uint8_t mask) {
  std::uint8_t a[] = {mask};
  return scan(scan_op::ClearStatus, a);
}
Bytes set_special_status(std::uint8_t mask) {
  std::uint8_t a[] = {mask};
  return scan(scan_op::SetSpecialStatus, a);
}
Bytes clear_special_status(std::uint8_t mask) {
  std::uint8_t a[] = {mask};
  return scan(scan_op::ClearSpecialStatus, a);
}
Bytes output_special_status() { return scan(scan_op::OutputSpecialStatus); }
Bytes output_type() { return scan(scan_op::OutputType); }
Bytes output_serial() { return scan(scan_op::OutputSerialNumber); }
Bytes output_part() { return scan(scan_op::OutputArticleNumber); }
Bytes output_date() { return scan(scan_op::OutputProductionDate); }
Bytes output_firmware() { return scan(scan_op::OutputSoftwareVersion); }
}  // namespace req

Request parse_request(std::span<const std::uint8_t> body) {
  if (body.empty()) throw Error(ErrorClass::protocol_error, "Spectrolino request has an empty body");
  Request r;
  if (body[0] == kScanRequestPrefix) {
    if (body.size() < 2) throw Error(ErrorClass::protocol_error, "SpectroScan request D0 has no opcode");
    r.scan = true;
    r.opcode = body[1];
    r.args.assign(body.begin() + 2, body.end());
  } else {
    r.opcode = body[0];
    r.args.assign(body.begin() + 1, body.end());
  }
  return r;
}

AnswerHead answer_head(std::span<const std::uint8_t> body) {
  if (body.empty()) throw Error(ErrorClass::protocol_error, "Spectrolino answer has an empty body");
  if (body[0] == kScanAnswerPrefix) {
    if (body.size() < 2) throw Error(ErrorClass::protocol_error, "SpectroScan answer D1 has no answer code");
    return {true, body[1]};
  }
  return {false, body[0]};
}

// ---------------------------------------------------------------- Spectrolino answers

Bytes DownloadError::encode() const { return answer(ans::DownloadError).u16(remote_errors).take(); }
DownloadError DownloadError::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::DownloadError, "DownloadError");
  DownloadError a;
  a.remote_errors = r.u16("remote error set");
  r.finish();
  return a;
}

Bytes ExecError::encode() const { return answer(ans::ExecError).u8(error).take(); }
ExecError ExecError::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::ExecError, "ExecError");
  ExecError a;
  a.error = r.u8("error");
  r.finish();
  return a;
}

Bytes ActError::encode() const { return answer(ans::ActErrorAnswer).u8(error).take(); }
ActError ActError::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::ActErrorAnswer, "ActErrorAnswer");
  ActError a;
  a.error = r.u8("error");
  r.finish();
  return a;
}

Bytes ComError::encode() const { return answer(ans::ComError).u8(error).take(); }
ComError ComError::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::ComError, "ComError");
  ComError a;
  a.error = r.u8("COM error");
  r.finish();
  return a;
}

Bytes ParameterAnswer::encode() const {
  return answer(ans::ParameterAnswer)
      .u8(u8_of(density_standard))
      .u8(u8_of(white_base))
      .u8(u8_of(illuminant))
      .u8(u8_of(observer))
      .u8(u8_of(filter))
      .take();
}
ParameterAnswer ParameterAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::ParameterAnswer, "ParameterAnswer");
  ParameterAnswer a;
  a.density_standard = static_cast<DensityStandard>(r.u8("density standard"));
  a.white_base = static_cast<WhiteBase>(r.u8("white base"));
  a.illuminant = static_cast<Illuminant>(r.u8("illuminant"));
  a.observer = static_cast<Observer>(r.u8("observer"));
  a.filter = static_cast<Filter>(r.u8("filter"));
  r.finish();
  return a;
}

Bytes MeasControlAnswer::encode() const {
  return answer(ans::MeasControlAnswer).u8(ctt).u8(value).u16(remote_errors).take();
}
MeasControlAnswer MeasControlAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::MeasControlAnswer, "MeasControlAnswer");
  MeasControlAnswer a;
  a.ctt = r.u8("control type");
  a.value = r.u8("value");
  a.remote_errors = r.u16("remote error set");
  r.finish();
  return a;
}

Bytes DeviceDataAnswer::encode() const {
  return answer(ans::DeviceDataAnswer)
      .str(name, kNameLen)
      .u8(device_no)
      .str(part_no, kPartLen)
      .u32(serial)
      .str(software, kSoftwareLen)
      .str(reserved, kReservedLen)
      .take();
}
DeviceDataAnswer DeviceDataAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::DeviceDataAnswer, "DeviceDataAnswer");
  DeviceDataAnswer a;
  a.name = r.str(kNameLen, "name");
  a.device_no = r.u8("device number");
  a.part_no = r.str(kPartLen, "part number");
  a.serial = r.u32("serial number");
  a.software = r.str(kSoftwareLen, "software version");
  a.reserved = r.str(kReservedLen, "reserved");
  r.finish();
  return a;
}

Bytes TargetIdAnswer::encode() const {
  return answer(ans::TargetIdAnswer)
      .str(name, kNameLen)
      .u16(serial)
      .u16(sw_release)
      .u16(year)
      .u16(month)
      .u16(day)
      .u16(hour)
      .u16(minute)
      .u8(target_tech)
      .u16(first_wavelength)
      .u16(bands)
      .u16(step)
      .take();
}
TargetIdAnswer TargetIdAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::TargetIdAnswer, "TargetIdAnswer");
  TargetIdAnswer a;
  a.name = r.str(kNameLen, "name");
  a.serial = r.u16("serial number");
  a.sw_release = r.u16("software release");
  a.year = r.u16("year");
  a.month = r.u16("month");
  a.day = r.u16("day");
  a.hour = r.u16("hour");
  a.minute = r.u16("minute");
  a.target_tech = r.u8("target tech");
  a.first_wavelength = r.u16("first wavelength");
  a.bands = r.u16("number of wavelengths");
  a.step = r.u16("wavelength step");
  r.finish();
  return a;
}

Bytes WhiteReferenceAnswer::encode() const {
  return answer(ans::WhiteReferenceAnswer).u8(u8_of(filter)).floats(reference).u8(origin).str(name, kNameLen).take();
}
WhiteReferenceAnswer WhiteReferenceAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::WhiteReferenceAnswer, "WhiteReferenceAnswer");
  WhiteReferenceAnswer a;
  a.filter = static_cast<Filter>(r.u8("filter"));
  a.reference = r.spectrum("white reference");
  a.origin = r.u8("original-reference flag");
  a.name = r.str(kNameLen, "table name");
  r.finish();
  return a;
}

Bytes IllumTabAnswer::encode() const {
  return answer(ans::IllumTabAnswer).u8(0x00).u8(illuminant).floats(table).u16(remote_errors).take();
}
IllumTabAnswer IllumTabAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::IllumTabAnswer, "IllumTabAnswer");
  IllumTabAnswer a;
  r.literal(0x00, "table selector");
  a.illuminant = r.u8("illuminant");
  a.table = r.spectrum("illuminant table");
  a.remote_errors = r.u16("remote error set");
  r.finish();
  return a;
}

Bytes ValNrAnswer::encode() const { return answer(ans::ValNrAnswer).u8(0x60).u8(kelvin_over_100).u16(remote_errors).take(); }
ValNrAnswer ValNrAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::ValNrAnswer, "ValNrAnswer");
  ValNrAnswer a;
  r.literal(0x60, "value selector");
  a.kelvin_over_100 = r.u8("temperature/100");
  a.remote_errors = r.u16("remote error set");
  r.finish();
  return a;
}

Bytes FloatAnswer::encode() const { return answer(ans::FloatAnswer).u8(type).f32(value).take(); }
FloatAnswer FloatAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::FloatAnswer, "FloatAnswer");
  FloatAnswer a;
  a.type = r.u8("type");
  a.value = r.f32("value");
  r.finish();
  return a;
}

Bytes SlopeAnswer::encode() const { return answer(ans::SlopeAnswer).floats(slope).take(); }
SlopeAnswer SlopeAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::SlopeAnswer, "SlopeAnswer");
  SlopeAnswer a;
  for (auto& v : a.slope) v = r.f32("slope");
  r.finish();
  return a;
}

Bytes NewMeasureAnswer::encode() const { return answer(ans::NewMeasureAnswer).u8(u8_of(what)).u8(kDummy09).take(); }
NewMeasureAnswer NewMeasureAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::NewMeasureAnswer, "NewMeasureAnswer");
  NewMeasureAnswer a;
  a.what = static_cast<NewMeasurement>(r.u8("new measurement"));
  r.literal(kDummy09, "09");
  r.finish();
  return a;
}

Bytes NewKeyAnswer::encode() const { return answer(ans::NewKeyAnswer).u8(new_key).u16(key).take(); }
NewKeyAnswer NewKeyAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::NewKeyAnswer, "NewKeyAnswer");
  NewKeyAnswer a;
  a.new_key = r.u8("new key");
  a.key = r.u16("key");
  r.finish();
  return a;
}

Bytes SpecParameterAnswer::encode() const {
  return answer(ans::SpecParameterAnswer)
      .u8(kDummy09)
      .u8(u8_of(type))
      .floats(spectrum)
      .u8(ref_valid)
      .u8(u8_of(filter))
      .u8(u8_of(white_base))
      .u8(kLiteral02)
      .u16(remote_errors)
      .take();
}
SpecParameterAnswer SpecParameterAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::SpecParameterAnswer, "SpecParameterAnswer");
  SpecParameterAnswer a;
  r.literal(kDummy09, "09");
  a.type = static_cast<SpectrumType>(r.u8("spectrum type"));
  a.spectrum = r.spectrum("spectrum");
  a.ref_valid = r.u8("reference valid");
  a.filter = static_cast<Filter>(r.u8("filter"));
  a.white_base = static_cast<WhiteBase>(r.u8("white base"));
  r.literal(kLiteral02, "02");
  a.remote_errors = r.u16("remote error set");
  r.finish();
  return a;
}

Bytes SpectrumAnswer::encode() const {
  return answer(ans::SpectrumAnswer)
      .u8(kDummy09)
      .u8(u8_of(type))
      .floats(spectrum)
      .u8(ref_valid)
      .u16(remote_errors)
      .take();
}
SpectrumAnswer SpectrumAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::SpectrumAnswer, "SpectrumAnswer");
  SpectrumAnswer a;
  r.literal(kDummy09, "09");
  a.type = static_cast<SpectrumType>(r.u8("spectrum type"));
  a.spectrum = r.spectrum("spectrum");
  a.ref_valid = r.u8("reference valid");
  a.remote_errors = r.u16("remote error set");
  r.finish();
  return a;
}

Bytes CParameterAnswer::encode() const {
  return answer(ans::CParameterAnswer)
      .u8(kDummy09)
      .u8(u8_of(type))
      .floats(values)
      .u8(ref_valid)
      .u8(u8_of(filter))
      .u8(u8_of(white_base))
      .u8(kLiteral02)
      .u8(u8_of(illuminant))
      .u8(u8_of(observer))
      .u16(remote_errors)
      .take();
}
CParameterAnswer CParameterAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::CParameterAnswer, "CParameterAnswer");
  CParameterAnswer a;
  r.literal(kDummy09, "09");
  a.type = static_cast<ColourType>(r.u8("colour type"));
  for (auto& v : a.values) v = r.f32("colour value");
  a.ref_valid = r.u8("reference valid");
  a.filter = static_cast<Filter>(r.u8("filter"));
  a.white_base = static_cast<WhiteBase>(r.u8("white base"));
  r.literal(kLiteral02, "02");
  a.illuminant = static_cast<Illuminant>(r.u8("illuminant"));
  a.observer = static_cast<Observer>(r.u8("observer"));
  a.remote_errors = r.u16("remote error set");
  r.finish();
  return a;
}

Bytes CAnswer::encode() const {
  return answer(ans::CAnswer).u8(kDummy09).u8(u8_of(type)).floats(values).u8(ref_valid).u16(remote_errors).take();
}
CAnswer CAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::CAnswer, "CAnswer");
  CAnswer a;
  r.literal(kDummy09, "09");
  a.type = static_cast<ColourType>(r.u8("colour type"));
  for (auto& v : a.values) v = r.f32("colour value");
  a.ref_valid = r.u8("reference valid");
  a.remote_errors = r.u16("remote error set");
  r.finish();
  return a;
}

Bytes DensityParameterAnswer::encode() const {
  return answer(ans::DensityParameterAnswer)
      .u8(kDummy09)
      .floats(density)
      .u8(std_density_filter)
      .u8(ref_valid)
      .u8(u8_of(filter))
      .u8(u8_of(white_base))
      .u8(kLiteral02)
      .u8(u8_of(density_standard))
      .u16(remote_errors)
      .take();
}
DensityParameterAnswer DensityParameterAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::DensityParameterAnswer, "DensityParameterAnswer");
  DensityParameterAnswer a;
  r.literal(kDummy09, "09");
  for (auto& v : a.density) v = r.f32("density");
  a.std_density_filter = r.u8("standard density filter");
  a.ref_valid = r.u8("reference valid");
  a.filter = static_cast<Filter>(r.u8("filter"));
  a.white_base = static_cast<WhiteBase>(r.u8("white base"));
  r.literal(kLiteral02, "02");
  a.density_standard = static_cast<DensityStandard>(r.u8("density standard"));
  a.remote_errors = r.u16("remote error set");
  r.finish();
  return a;
}

Bytes DensityAnswer::encode() const {
  return answer(ans::DensityAnswer)
      .u8(kDummy09)
      .floats(density)
      .u8(std_density_filter)
      .u8(ref_valid)
      .u16(remote_errors)
      .take();
}
DensityAnswer DensityAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::DensityAnswer, "DensityAnswer");
  DensityAnswer a;
  r.literal(kDummy09, "09");
  for (auto& v : a.density) v = r.f32("density");
  a.std_density_filter = r.u8("standard density filter");
  a.ref_valid = r.u8("reference valid");
  a.remote_errors = r.u16("remote error set");
  r.finish();
  return a;
}

Bytes DmaxAnswer::encode() const {
  return answer(ans::DmaxAnswer)
      .u8(kDummy09)
      .f32(dmax)
      .u16(wavelength)
      .u8(dmax_ok)
      .u8(ref_valid)
      .u16(remote_errors)
      .take();
}
DmaxAnswer DmaxAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open(body, ans::DmaxAnswer, "DmaxAnswer");
  DmaxAnswer a;
  r.literal(kDummy09, "09");
  a.dmax = r.f32("dmax");
  a.wavelength = r.u16("wavelength");
  a.dmax_ok = r.u8("dmax ok");
  a.ref_valid = r.u8("reference valid");
  a.remote_errors = r.u16("remote error set");
  r.finish();
  return a;
}

// ---------------------------------------------------------------- SpectroScan answers

Bytes ScanErrorAnswer::encode() const { return scan_answer(scan_ans::ErrorAnswer).u8(error).take(); }
ScanErrorAnswer ScanErrorAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open_scan(body, scan_ans::ErrorAnswer, "ErrorAnswer");
  ScanErrorAnswer a;
  a.error = r.u8("scan error");
  r.finish();
  return a;
}

Bytes ScanComErrorAnswer::encode() const { return scan_answer(scan_ans::ComErrorAnswer).u8(error).take(); }
ScanComErrorAnswer ScanComErrorAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open_scan(body, scan_ans::ComErrorAnswer, "ComErrorAnswer");
  ScanComErrorAnswer a;
  a.error = r.u8("COM error");
  r.finish();
  return a;
}

Bytes PositionAnswer::encode() const {
  return scan_answer(scan_ans::PositionAnswer).u8(u8_of(ref)).u16(remaining).u16(x).u16(y).u8(z).take();
}
PositionAnswer PositionAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open_scan(body, scan_ans::PositionAnswer, "PositionAnswer");
  PositionAnswer a;
  a.ref = static_cast<ScanRef>(r.u8("reference"));
  a.remaining = r.u16("remaining");
  a.x = r.u16("x");
  a.y = r.u16("y");
  a.z = r.u8("z");
  r.finish();
  return a;
}

Bytes KeyAnswer::encode() const { return scan_answer(scan_ans::KeyAnswer).u8(keys).u8(long_press).take(); }
KeyAnswer KeyAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open_scan(body, scan_ans::KeyAnswer, "KeyAnswer");
  KeyAnswer a;
  a.keys = r.u8("keys");
  a.long_press = r.u8("press time");
  r.finish();
  return a;
}

Bytes StatusAnswer::encode() const { return scan_answer(scan_ans::StatusAnswer).u8(bits).take(); }
StatusAnswer StatusAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open_scan(body, scan_ans::StatusAnswer, "StatusAnswer");
  StatusAnswer a;
  a.bits = r.u8("status bits");
  r.finish();
  return a;
}

Bytes TypeAnswer::encode() const { return scan_answer(scan_ans::TypeAnswer).str(name, kNameLen).take(); }
TypeAnswer TypeAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open_scan(body, scan_ans::TypeAnswer, "TypeAnswer");
  TypeAnswer a;
  a.name = r.str(kNameLen, "type name");
  r.finish();
  return a;
}

Bytes SerialNumberAnswer::encode() const { return scan_answer(scan_ans::SerialNumberAnswer).u32(serial).take(); }
SerialNumberAnswer SerialNumberAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open_scan(body, scan_ans::SerialNumberAnswer, "SerialNumberAnswer");
  SerialNumberAnswer a;
  a.serial = r.u32("serial number");
  r.finish();
  return a;
}

Bytes ArticleNumberAnswer::encode() const { return scan_answer(scan_ans::ArticleNumberAnswer).str(part, kPartLen).take(); }
ArticleNumberAnswer ArticleNumberAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open_scan(body, scan_ans::ArticleNumberAnswer, "ArticleNumberAnswer");
  ArticleNumberAnswer a;
  a.part = r.str(kPartLen, "article number");
  r.finish();
  return a;
}

Bytes ProductionDateAnswer::encode() const {
  return scan_answer(scan_ans::ProductionDateAnswer).u16(day).u16(month).u16(year).take();
}
ProductionDateAnswer ProductionDateAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open_scan(body, scan_ans::ProductionDateAnswer, "ProductionDateAnswer");
  ProductionDateAnswer a;
  a.day = r.u16("day");
  a.month = r.u16("month");
  a.year = r.u16("year");
  r.finish();
  return a;
}

Bytes SoftwareVersionAnswer::encode() const {
  return scan_answer(scan_ans::SoftwareVersionAnswer).str(version, kSoftwareLen).take();
}
SoftwareVersionAnswer SoftwareVersionAnswer::decode(std::span<const std::uint8_t> body) {
  auto r = open_scan(body, scan_ans::SoftwareVersionAnswer, "SoftwareVersionAnswer");
  SoftwareVersionAnswer a;
  a.version = r.str(kSoftwareLen, "software version");
  r.finish();
  return a;
}

}  // namespace colorlab::wire::spectrolino
