// Byte-exact checks of the Spectrolino/SpectroScan codec against the examples observed on a pty
// with Argyll spotread (instrument-protocols.md §1.2, §5.4).
#include <gtest/gtest.h>

#include "colorlab/wire/spectrolino_protocol.hpp"

namespace sp = colorlab::wire::spectrolino;
using colorlab::Error;
using colorlab::ErrorClass;

namespace {

ErrorClass class_of(auto&& fn) {
  try {
    fn();
  } catch (const Error& e) {
    return e.cls();
  }
  return ErrorClass::internal;
}

}  // namespace

TEST(SimWireSpectrolino, ParameterRequestAndAnswerBytes) {
  EXPECT_EQ(sp::frame_request(sp::req::parameter_request()), ";00\r\n");
  sp::ParameterAnswer a;  // ANSI T, absolute, D50, 2 deg, no filter
  EXPECT_EQ(sp::frame_answer(a.encode()), ":0B0101030001\r\n");
  auto d = sp::ParameterAnswer::decode(sp::unframe_answer(":0B0101030001\r\n"));
  EXPECT_EQ(d.illuminant, sp::Illuminant::D50);
  EXPECT_EQ(d.filter, sp::Filter::None);
}

TEST(SimWireSpectrolino, FloatIsLittleEndianIeee) {
  sp::Writer w;
  w.f32(0.9f).u16(380);
  EXPECT_EQ(sp::to_hex(w.bytes()), "6666663F7C01");
  sp::Reader r(w.bytes(), "test");
  EXPECT_FLOAT_EQ(r.f32("f"), 0.9f);
  EXPECT_EQ(r.u16("u"), 380);
  r.finish();
}

TEST(SimWireSpectrolino, TargetIdAnswerMatchesObservedBytes) {
  sp::TargetIdAnswer t;
  t.name = "Spectrolino";
  t.serial = 12345;
  t.sw_release = 100;
  t.year = 1999;
  t.month = 6;
  t.day = 15;
  t.hour = 12;
  t.minute = 0;
  std::string expected = ":31" + std::string("5370656374726F6C696E6F") + std::string(14, '0') + "3930" + "6400" +
                         "CF07" + "0600" + "0F00" + "0C00" + "0000" + "02" + "7C01" + "2400" + "0A00" + "\r\n";
  EXPECT_EQ(sp::frame_answer(t.encode()), expected);
  auto d = sp::TargetIdAnswer::decode(sp::unframe_answer(expected));
  EXPECT_EQ(d.name, "Spectrolino");
  EXPECT_EQ(d.serial, 12345);
  EXPECT_EQ(d.year, 1999);
  EXPECT_EQ(d.bands, 36);
}

TEST(SimWireSpectrolino, ArgyllRequestsEncodeExactly) {
  EXPECT_EQ(sp::frame_request(sp::req::scan(sp::scan_op::OutputStatus)), ";D024\r\n");
  EXPECT_EQ(sp::frame_request(sp::req::meas_control_download(sp::ctt::HandshakeHardware)), ";4DCF\r\n");
  EXPECT_EQ(sp::frame_request(sp::req::meas_control_download(sp::ctt::Baud9600)), ";4D27\r\n");
  EXPECT_EQ(sp::frame_request(sp::req::reset_status(0x05)), ";5A010405\r\n");
  EXPECT_EQ(sp::frame_request(sp::req::parameter_download(sp::DensityStandard::AnsiT, sp::WhiteBase::Absolute,
                                                          sp::Illuminant::D50, sp::Observer::Deg2)),
            ";1601010300\r\n");
  EXPECT_EQ(sp::frame_request(sp::req::target_on_off(true)), ";33000100\r\n");
  EXPECT_EQ(sp::frame_request(sp::req::target_on_off(false)), ";33000000\r\n");
  EXPECT_EQ(sp::frame_request(sp::req::white_reference_request(sp::Filter::None)), ";B301\r\n");
  EXPECT_EQ(sp::frame_request(sp::req::exec_ref_measurement(sp::RefMode::WhiteCalWarn)), ";220907\r\n");
  EXPECT_EQ(sp::frame_request(sp::req::c_parameter_request(sp::ColourType::XYZ)), ";BA0904\r\n");
  EXPECT_EQ(sp::frame_request(sp::req::spec_parameter_request(sp::SpectrumType::Reflectance)), ";B80900\r\n");
  EXPECT_EQ(sp::frame_request(sp::req::move_absolute(sp::ScanRef::Sight, 3100, 2300)), ";D000011C0CFC08\r\n");
  EXPECT_EQ(sp::frame_request(sp::req::move_and_measure(380, 10)), ";D0077C010A00\r\n");
  EXPECT_EQ(sp::frame_request(sp::req::change_baud(0x07)), ";D02007\r\n");
}

TEST(SimWireSpectrolino, SmallAnswersMatchObservedBytes) {
  EXPECT_EQ(sp::frame_answer(sp::ComError{sp::com_err::IllegalRecType}.encode()), ":2604\r\n");
  EXPECT_EQ(sp::frame_answer(sp::DownloadError{0}.encode()), ":1F0000\r\n");
  EXPECT_EQ(sp::frame_answer(sp::ExecError{sp::exec_err::WhiteMeasOK}.encode()), ":2513\r\n");
  EXPECT_EQ(sp::frame_answer(sp::ExecError{0}.encode()), ":2500\r\n");
  EXPECT_EQ(sp::frame_answer(sp::NewMeasureAnswer{sp::NewMeasurement::Measurement}.encode()), ":120109\r\n");
  EXPECT_EQ(sp::frame_answer(sp::StatusAnswer{sp::status::Online}.encode()), ":D18310\r\n");
  EXPECT_EQ(sp::frame_answer(sp::ScanErrorAnswer{sp::scan_err::DeviceIsOffline}.encode()), ":D18001\r\n");
}

TEST(SimWireSpectrolino, AnswerFieldCountsMatchArgyll) {
  // Lengths in hex characters, including ':' and CR LF; Argyll rejects any other count.
  EXPECT_EQ(sp::frame_answer(sp::SpecParameterAnswer{}.encode()).size(), 1 + 2 * (1 + 2 + 144 + 4 + 2) + 2);
  EXPECT_EQ(sp::frame_answer(sp::CParameterAnswer{}.encode()).size(), 1 + 2 * (1 + 2 + 12 + 6 + 2) + 2);
  EXPECT_EQ(sp::frame_answer(sp::DeviceDataAnswer{}.encode()).size(), 1 + 2 * (1 + 18 + 1 + 8 + 4 + 12 + 16) + 2);
  EXPECT_EQ(sp::frame_answer(sp::WhiteReferenceAnswer{}.encode()).size(), 1 + 2 * (1 + 1 + 144 + 1 + 18) + 2);
  EXPECT_EQ(sp::frame_answer(sp::TypeAnswer{"SpectroScanT"}.encode()).size(), 1 + 2 * (2 + 18) + 2);
  EXPECT_GE(sp::frame_answer(sp::TypeAnswer{"SpectroScanT"}.encode()).size() - 2, 41u);
}

TEST(SimWireSpectrolino, RoundTripsEveryAnswer) {
  sp::SpecParameterAnswer s;
  for (std::size_t i = 0; i < sp::kSpectrumBands; ++i) s.spectrum[i] = 0.01f * static_cast<float>(i);
  EXPECT_EQ(sp::SpecParameterAnswer::decode(s.encode()).spectrum, s.spectrum);
  sp::CParameterAnswer c;
  c.values = {41.2f, 43.5f, 33.1f};
  EXPECT_EQ(sp::CParameterAnswer::decode(c.encode()).values, c.values);
  sp::SpectrumAnswer m;
  m.spectrum[3] = 0.5f;
  EXPECT_EQ(sp::SpectrumAnswer::decode(m.encode()).spectrum[3], 0.5f);
  sp::PositionAnswer p{sp::ScanRef::Sight, 0, 1234, 567, 1};
  auto pd = sp::PositionAnswer::decode(p.encode());
  EXPECT_EQ(pd.x, 1234);
  EXPECT_EQ(pd.y, 567);
  EXPECT_EQ(pd.z, 1);
  EXPECT_EQ(sp::DeviceDataAnswer::decode(sp::DeviceDataAnswer{"Spectrolino", 0x20, "36.77.91", 12345, "V1.00", ""}.encode())
                .serial,
            12345u);
  EXPECT_EQ(sp::TypeAnswer::decode(sp::TypeAnswer{"SpectroScanT"}.encode()).name, "SpectroScanT");
  EXPECT_EQ(sp::ProductionDateAnswer::decode(sp::ProductionDateAnswer{15, 6, 1999}.encode()).year, 1999);
  EXPECT_EQ(sp::MeasControlAnswer::decode(sp::MeasControlAnswer{0x9B, 1, 0}.encode()).ctt, 0x9B);
  EXPECT_EQ(sp::DmaxAnswer::decode(sp::DmaxAnswer{1.5f, 620, 1, 1, 0}.encode()).wavelength, 620);
}

TEST(SimWireSpectrolino, MalformedFramesThrowTypedErrors) {
  EXPECT_EQ(class_of([] { sp::unframe_answer("0B01\r\n"); }), ErrorClass::coms_fail);
  EXPECT_EQ(class_of([] { sp::unframe_answer(":0B0\r\n"); }), ErrorClass::coms_fail);
  EXPECT_EQ(class_of([] { sp::unframe_answer(":0BZZ\r\n"); }), ErrorClass::coms_fail);
  EXPECT_EQ(class_of([] { sp::ParameterAnswer::decode(sp::unframe_answer(":0B01010300\r\n")); }),
            ErrorClass::protocol_error);
  EXPECT_EQ(class_of([] { sp::ParameterAnswer::decode(sp::unframe_answer(":0B010103000100\r\n")); }),
            ErrorClass::protocol_error);
  EXPECT_EQ(class_of([] { sp::NewMeasureAnswer::decode(sp::unframe_answer(":120108\r\n")); }),
            ErrorClass::protocol_error);
  // A COM error where a parameter answer was expected names the COM error.
  try {
    sp::ParameterAnswer::decode(sp::unframe_answer(":2604\r\n"));
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("illegal record type"), std::string::npos) << e.what();
    EXPECT_EQ(e.info().device_code, "spectrolino-com:04");
  }
}

TEST(SimWireSpectrolino, ErrorTablesFollowArgyllClassification) {
  EXPECT_EQ(sp::describe_exec_error(0x13).argyll, sp::ArgyllClass::notify);
  EXPECT_EQ(sp::describe_exec_error(0x34).argyll, sp::ArgyllClass::notify);
  EXPECT_EQ(sp::describe_exec_error(0x32).argyll, sp::ArgyllClass::warning);
  EXPECT_EQ(sp::describe_exec_error(0x07).argyll, sp::ArgyllClass::comms_fail);
  EXPECT_EQ(sp::describe_exec_error(0x0E).argyll, sp::ArgyllClass::misread);
  EXPECT_EQ(sp::describe_exec_error(0x04).argyll, sp::ArgyllClass::hardware);
  EXPECT_EQ(sp::describe_exec_error(0x04).meaning, "lamp failure");
  EXPECT_EQ(sp::describe_scan_error(0x07).argyll, sp::ArgyllClass::misread);
  EXPECT_EQ(sp::describe_scan_error(0x03).argyll, sp::ArgyllClass::hardware);
  EXPECT_EQ(sp::describe_scan_error(0x05).argyll, sp::ArgyllClass::unsupported);
  EXPECT_FALSE(sp::describe_exec_error(0x03).known);
  auto bits = sp::describe_remote_errors(0x0104);
  ASSERT_EQ(bits.size(), 2u);
  EXPECT_EQ(bits[0].meaning, "no valid illuminant");
  EXPECT_EQ(bits[1].meaning, "slope out of range");
  EXPECT_NO_THROW(sp::throw_on_exec_error(0x13, "white cal", {0x13}));
  EXPECT_EQ(class_of([] { sp::throw_on_exec_error(0x04, "measure"); }), ErrorClass::hardware_fail);
  EXPECT_EQ(class_of([] { sp::throw_on_exec_error(0x37, "measure"); }), ErrorClass::needs_calibration);
  EXPECT_EQ(class_of([] { sp::throw_on_scan_error(0x01, "move"); }), ErrorClass::needs_operator);
  EXPECT_EQ(class_of([] { sp::throw_on_remote_error(0x0400, "spectrum"); }), ErrorClass::misread);
}

TEST(SimWireSpectrolino, SpeedCodes) {
  EXPECT_EQ(sp::ctt_baud(0x27), 9600);
  EXPECT_EQ(sp::ctt_baud(0x28), 19200);
  EXPECT_EQ(sp::ctt_baud(0x99), 57600);
  EXPECT_EQ(sp::ctt_baud(0x9B), std::nullopt);
  EXPECT_EQ(sp::baud_ctt(4800), 0x26);
  EXPECT_EQ(sp::scan_bt_baud(0x07), 9600);
  EXPECT_EQ(sp::scan_bt_baud(0x09), 28800);
  EXPECT_EQ(sp::baud_scan_bt(57600), 0x0A);
  EXPECT_EQ(sp::illuminant_name(sp::Illuminant::F11), "F11");
}
