#pragma once
// The GretagMacbeth Spectrolino / SpectroScan (T) hex wire format as pure functions, shared by the
// driver, the simulator and the tests (instrument-protocols.md §1). A request is ';' + hex + CR LF,
// an answer ':' + hex + CR LF; integers and IEEE-754 floats travel least-significant byte first.
// SpectroScan requests start with D0 and its answers with D1.
//
// Decoders throw colorlab::Error: coms_fail for bytes that are not a frame (missing ':' or CR LF,
// bad hex), protocol_error for a well-formed frame with the wrong answer code or field count.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "colorlab/core/error.hpp"

namespace colorlab::wire::spectrolino {

using Bytes = std::vector<std::uint8_t>;

inline constexpr std::size_t kSpectrumBands = 36;  // 380..730 nm in 10 nm steps
inline constexpr int kFirstWavelength = 380;
inline constexpr int kWavelengthStep = 10;
using Spectrum = std::array<float, kSpectrumBands>;

// Fixed string field lengths (§1.2).
inline constexpr std::size_t kNameLen = 18;
inline constexpr std::size_t kPartLen = 8;
inline constexpr std::size_t kSoftwareLen = 12;
inline constexpr std::size_t kReservedLen = 16;

// Argyll's literal "dummy" bytes.
inline constexpr std::uint8_t kDummy09 = 0x09;
inline constexpr std::uint8_t kLiteral02 = 0x02;
inline constexpr std::uint8_t kScanRequestPrefix = 0xD0;
inline constexpr std::uint8_t kScanAnswerPrefix = 0xD1;

// ---------------------------------------------------------------- framing and fields

std::string to_hex(std::span<const std::uint8_t> bytes);  // uppercase, 2 digits per byte
// Accepts upper- and lowercase; `where` names the frame for the error message.
Bytes from_hex(std::string_view hex, std::string_view where = "frame");

std::string frame_request(std::span<const std::uint8_t> body);  // ";" + HEX + "\r\n"
std::string frame_answer(std::span<const std::uint8_t> body);   // ":" + HEX + "\r\n"
// Strip the lead character and CR LF (trailing CR/LF optional) and decode the hex body.
Bytes unframe_request(std::string_view line);
Bytes unframe_answer(std::string_view line);

// Appends little-endian fields.
class Writer {
 public:
  Writer& u8(std::uint8_t v);
  Writer& u16(std::uint16_t v);
  Writer& u32(std::uint32_t v);
  Writer& f32(float v);
  Writer& floats(std::span<const float> v);
  Writer& str(std::string_view s, std::size_t len);  // padded with 00, truncated to len
  Writer& raw(std::span<const std::uint8_t> b);
  const Bytes& bytes() const { return out_; }
  Bytes take() { return std::move(out_); }

 private:
  Bytes out_;
};

// Reads little-endian fields; every short read or leftover throws protocol_error naming `what`.
class Reader {
 public:
  Reader(std::span<const std::uint8_t> bytes, std::string what);
  std::uint8_t u8(std::string_view field);
  std::uint16_t u16(std::string_view field);
  std::uint32_t u32(std::string_view field);
  float f32(std::string_view field);
  Spectrum spectrum(std::string_view field);
  std::string str(std::size_t len, std::string_view field);  // stops at the first 00
  void literal(std::uint8_t expected, std::string_view field);
  void finish();  // throws when bytes are left over
  std::size_t remaining() const { return bytes_.size() - pos_; }
  std::size_t position() const { return pos_; }

 private:
  void need(std::size_t n, std::string_view field);
  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
  std::string what_;
};

// ---------------------------------------------------------------- enumerations (§1.4)

namespace op {  // Spectrolino request opcodes
inline constexpr std::uint8_t ParameterRequest = 0x00, DensitySlopeRequest = 0x01, DensityRequest = 0x03,
                              DmaxRequest = 0x04, SpectrumRequest = 0x05, CRequest = 0x06,
                              NewMeasureRequest = 0x07, NewKeyRequest = 0x08, ParameterDownload = 0x16,
                              SlopeDownload = 0x17, ExecMeasurement = 0x20, ExecWhiteMeasurement = 0x21,
                              ExecRefMeasurement = 0x22, ActErrorRequest = 0x29, TargetIdRequest = 0x2B,
                              TargetOnOffStDownload = 0x33, IllumTabRequest = 0x38, IllumTabDownload = 0x3A,
                              DensTabRequest = 0x3B, DensTabDownload = 0x3D, GetValNr = 0x47,
                              ExecWhiteRefToOrigDat = 0x4A, MeasControlDownload = 0x4D,
                              ResetStatusDownload = 0x5A, MeasControlRequest = 0x5B,
                              SetMeasurementOutput = 0xB1, WhiteReferenceRequest = 0xB3,
                              DeviceDataRequest = 0xB5, WhiteReferenceDownld = 0xB7,
                              SpecParameterRequest = 0xB8, CParameterRequest = 0xBA,
                              DensityParameterRequest = 0xBD, FloatRequest = 0xC0, FloatDownload = 0xC2;
}  // namespace op

namespace ans {  // Spectrolino answer codes
inline constexpr std::uint8_t ParameterAnswer = 0x0B, SlopeAnswer = 0x0C, DensityAnswer = 0x0E,
                              DmaxAnswer = 0x0F, SpectrumAnswer = 0x10, CAnswer = 0x11,
                              NewMeasureAnswer = 0x12, NewKeyAnswer = 0x13, DownloadError = 0x1F,
                              ExecError = 0x25, ComError = 0x26, ActErrorAnswer = 0x2F, TargetIdAnswer = 0x31,
                              IllumTabAnswer = 0x39, DensTabAnswer = 0x3C, ValNrAnswer = 0x48,
                              MeasControlAnswer = 0x5C, WhiteReferenceAnswer = 0xB4, DeviceDataAnswer = 0xB6,
                              SpecParameterAnswer = 0xB9, CParameterAnswer = 0xBB,
                              DensityParameterAnswer = 0xBC, FloatAnswer = 0xC1;
}  // namespace ans

namespace scan_op {  // SpectroScan request opcodes (after D0)
inline constexpr std::uint8_t MoveAbsolut = 0x00, MoveRelative = 0x01, MoveHome = 0x02, MoveUp = 0x03,
                              MoveDown = 0x04, OutputActualPosition = 0x05, MoveToWhiteRefPos = 0x06,
                              MoveAndMeasure = 0x07, InitializeDevice = 0x0A, ScanSpectrolino = 0x0B,
                              InitMotorPosition = 0x0C, SetTableMode = 0x0D, SetLightLevel = 0x0E,
                              SetTransmStandbyPos = 0x0F, SetDeviceOnline = 0x10, SetDeviceOffline = 0x11,
                              HoldPaper = 0x12, ReleasePaper = 0x13, SetDigitizingMode = 0x14,
                              OutputDigitizedValues = 0x15, SetKeyAcknowlge = 0x16, ResetKeyAcknowlge = 0x17,
                              ChangeBaudRate = 0x20, ChangeHandshake = 0x21, OutputActualKey = 0x22,
                              OutputLastKey = 0x23, OutputStatus = 0x24, ClearStatus = 0x25,
                              SetSpecialStatus = 0x26, ClearSpecialStatus = 0x27, OutputSpecialStatus = 0x28,
                              OutputType = 0x30, OutputSerialNumber = 0x31, OutputArticleNumber = 0x32,
                              OutputProductionDate = 0x33, OutputSoftwareVersion = 0x34;
}  // namespace scan_op

namespace scan_ans {  // SpectroScan answer codes (after D1)
inline constexpr std::uint8_t ErrorAnswer = 0x80, PositionAnswer = 0x81, KeyAnswer = 0x82,
                              StatusAnswer = 0x83, TypeAnswer = 0x90, SerialNumberAnswer = 0x91,
                              ArticleNumberAnswer = 0x92, ProductionDateAnswer = 0x93,
                              SoftwareVersionAnswer = 0x94, ComErrorAnswer = 0xA0;
}  // namespace scan_ans

// MeasControl codes (ctt) for 4D / 5B.
namespace ctt {
inline constexpr std::uint8_t HandshakeXonXoff = 0x1E, HandshakeNone = 0x1F, HandshakeHardware = 0xCF,
                              Baud110 = 0x20, Baud150 = 0x21, Baud300 = 0x22, Baud600 = 0x23,
                              Baud1200 = 0x24, Baud2400 = 0x25, Baud4800 = 0x26, Baud9600 = 0x27,
                              Baud19200 = 0x28, Baud28800 = 0x98, Baud57600 = 0x99, SpeakerOn = 0x54,
                              SpeakerOff = 0x55, ModeReflectance = 0x9B, ModeTransmission = 0x9C,
                              ModeEmission = 0x9D, PhotometricAbsolute = 0x9E, PhotometricRelative = 0x9F,
                              CustomFilterSet = 0xA0, CustomFilterRelease = 0xA1;
}  // namespace ctt
// Baud rate of a MeasControl speed code, or nullopt when `code` is not a speed code.
std::optional<int> ctt_baud(std::uint8_t code);
std::optional<std::uint8_t> baud_ctt(int baud);

// SpectroScan ChangeBaudRate argument (ss_bt): 00=110 .. 0A=57600.
std::optional<int> scan_bt_baud(std::uint8_t bt);
std::optional<std::uint8_t> baud_scan_bt(int baud);

// Kept as laid out by hand: the manual's code tables, one line each.
// clang-format off
enum class Illuminant : std::uint8_t {
  A = 0x00, C = 0x01, D65 = 0x02, D50 = 0x03, User = 0x08, Dxx = 0x10,
  F1 = 0x18, F2 = 0x19, F3 = 0x1A, F4 = 0x1B, F5 = 0x1C, F6 = 0x1D, F7 = 0x1E, F8 = 0x1F,
  F9 = 0x20, F10 = 0x21, F11 = 0x22, F12 = 0x23,
};
bool valid_illuminant(std::uint8_t v);
std::string_view illuminant_name(Illuminant il);  // "D50", "F11", ...

enum class Observer : std::uint8_t { Deg2 = 0x00, Deg10 = 0x01 };
enum class WhiteBase : std::uint8_t { Paper = 0x00, Absolute = 0x01 };
enum class DensityStandard : std::uint8_t { AnsiA = 0x00, AnsiT = 0x01, Din = 0x02, DinNb = 0x03, User = 0x08 };
enum class Filter : std::uint8_t { Undefined = 0x00, None = 0x01, Polarising = 0x02, D65 = 0x03, UvCut = 0x05, Custom = 0x06 };
enum class ColourType : std::uint8_t {
  xyY = 0x00, Lab = 0x01, LChab = 0x02, Luv = 0x03, XYZ = 0x04, RxRyRz = 0x05, HLab = 0x06,
  LABmg = 0x0B, LCHmg = 0x0C, LCHuv = 0x0D,
};
enum class SpectrumType : std::uint8_t { Reflectance = 0x00, Density = 0x01 };
// ExecRefMeasurement (22 09 mode).
enum class RefMode : std::uint8_t { Normal = 0x00, WhiteCal = 0x01, WhiteCalWarn = 0x07, EmissionCal = 0x08 };
// NewMeasureAnswer nm.
enum class NewMeasurement : std::uint8_t { None = 0x00, Measurement = 0x01, WhiteCal = 0x02, WhiteCalWarn = 0x03, EmissionCal = 0x04 };
enum class ScanRef : std::uint8_t { Sensor = 0x00, Sight = 0x01 };
enum class TableMode : std::uint8_t { Reflectance = 0x00, Transmission = 0x01 };
enum class ScanHandshake : std::uint8_t { None = 0x00, XonXoff = 0x01, Hardware = 0x02 };
// clang-format on

inline constexpr std::uint8_t kDeviceNoSpectrolino = 0x20, kDeviceNoVideolino = 0x30, kDeviceNoSpectroScan = 0x40;
inline constexpr std::uint8_t kTargetTechSpectrolino = 0x02;

// SpectroScan status bits (D1 83) and special status bits (26/27/28).
namespace status {
inline constexpr std::uint8_t EnterPressed = 0x01, Online = 0x10, Digitizing = 0x20, KeyAck = 0x40, PaperHeld = 0x80;
inline constexpr std::uint8_t SpecialHeadDownWhileMoving = 0x01, SpecialTransmission = 0x10, SpecialAllLightsOn = 0x20;
}  // namespace status

// ---------------------------------------------------------------- error tables (§1.8)

// How Argyll classifies a code; simulator tests use this to check the client's view.
enum class ArgyllClass {
  ok,
  notify,
  warning,
  comms_fail,
  misread,
  hardware,
  unsupported,
  other
};
std::string_view to_string(ArgyllClass c);

struct CodeInfo {
  std::uint8_t code = 0;
  std::string_view meaning;
  ArgyllClass argyll = ArgyllClass::other;
  ErrorClass cls = ErrorClass::device_error;  // our classification for colorlab::Error
  bool known = false;
};

namespace exec_err {  // Error Type (1 byte), in ExecError 25 and ActErrorAnswer 2F
inline constexpr std::uint8_t NoError = 0x00, MemoryFailure = 0x01, PowerFailure = 0x02, LampFailure = 0x04,
                              HardwareFailure = 0x05, FilterOutOfPos = 0x06, SendTimeout = 0x07,
                              DriveError = 0x08, MeasDisabled = 0x09, DensCalibError = 0x0A,
                              EpromFailure = 0x0D, RemOverflow = 0x0E, MemoryError = 0x10, FullMemory = 0x11,
                              WhiteMeasOK = 0x13, NotReady = 0x15, WhiteMeasWarn = 0x32, ResetDone = 0x33,
                              EmissionCalOK = 0x34, OnlyEmission = 0x35, CheckSumWrong = 0x36,
                              NoValidMeas = 0x37, BackupError = 0x38, ProgramROMError = 0x3C;
}  // namespace exec_err
namespace scan_err {  // Scan Error (1 byte), in D1 80
inline constexpr std::uint8_t NoError = 0x00, DeviceIsOffline = 0x01, OutOfRange = 0x02, ProgrammingError = 0x03,
                              NoAccess = 0x04, NoCommand = 0x05, NoSpectrolino = 0x06, MeasError = 0x07,
                              NoTransmTable = 0x08, NotInTransmMode = 0x09, NotInReflectMode = 0x0A;
}  // namespace scan_err
namespace com_err {  // COM error (1 byte), in 26 xx and D1 A0 xx
inline constexpr std::uint8_t None = 0x00, StopButNoStart = 0x01, IllegalCharInRec = 0x02,
                              IncorrectRecLen = 0x03, IllegalRecType = 0x04, NoTagField = 0x06,
                              ConvError = 0x07, InvalidForEmission = 0x08, NoAccess = 0x10;
}  // namespace com_err
namespace remote_err {  // Remote Error Set (u16 bitmask)
inline constexpr std::uint16_t None = 0x0000, DensityStandard = 0x0001, WhiteStandard = 0x0002,
                               Illuminant = 0x0004, Observer = 0x0008, MaxLambda = 0x0010, Spectrum = 0x0020,
                               ColourSystem = 0x0040, Character = 0x0080, SlopeRange = 0x0100,
                               DensityRange = 0x0200, ReflectanceRange = 0x0400, Colour1Range = 0x0800,
                               Colour2Range = 0x1000, Colour3Range = 0x2000, NotSrOrBool = 0x4000,
                               NoValidValue = 0x8000;
}  // namespace remote_err

CodeInfo describe_exec_error(std::uint8_t code);
CodeInfo describe_scan_error(std::uint8_t code);
CodeInfo describe_com_error(std::uint8_t code);
struct RemoteBit {
  std::uint16_t bit;
  std::string_view meaning;
};
std::vector<RemoteBit> describe_remote_errors(std::uint16_t set);  // the bits that are set

// Throws a colorlab::Error describing the code unless it is a success/notify code for `op_name`
// (00 always; 13/34 when `success` says so). device_code is "spectrolino:XX" / "spectroscan:XX".
void throw_on_exec_error(std::uint8_t code, std::string_view op_name, std::initializer_list<std::uint8_t> success = {});
void throw_on_scan_error(std::uint8_t code, std::string_view op_name);
void throw_on_remote_error(std::uint16_t set, std::string_view op_name);

// ---------------------------------------------------------------- requests (bodies, unframed)

namespace req {
Bytes parameter_request();                                                               // 00
Bytes parameter_download(DensityStandard ds, WhiteBase wb, Illuminant il, Observer ob);  // 16 ds wb il ob
Bytes meas_control_download(std::uint8_t ctt);                                           // 4D ctt
Bytes meas_control_request(std::uint8_t ctt);                                            // 5B ctt
Bytes reset_status(std::uint8_t sm);                                                     // 5A 01 04 sm
Bytes white_ref_to_orig();                                                               // 4A
Bytes device_data_request();                                                             // B5
Bytes target_id_request();                                                               // 2B
Bytes white_reference_request(Filter f);                                                 // B3 f
Bytes white_reference_download(Filter f, const Spectrum& s, std::string_view name);      // B7
Bytes illum_tab_request(Illuminant il);                                                  // 38 00 il
Bytes illum_tab_download(const Spectrum& s);                                             // 3A 08 floats
Bytes dxx_temperature_request();                                                         // 47 60
Bytes dxx_temperature_set(std::uint16_t kelvin_over_100);                                // 3A 60 u16
Bytes float_request(std::uint8_t type);                                                  // C0 type
Bytes float_download(std::uint8_t type, float v);                                        // C2 type f
Bytes set_measurement_output(std::uint8_t type, std::uint8_t mask);                      // B1
Bytes exec_ref_measurement(RefMode mode);                                                // 22 09 mode
Bytes exec_white_measurement();                                                          // 21
Bytes exec_measurement();                                                                // 20
Bytes new_measure_request();                                                             // 07
Bytes new_key_request();                                                                 // 08
Bytes target_on_off(bool deactivated);                                                   // 33 00 oo 00
Bytes spec_parameter_request(SpectrumType t);                                            // B8 09 t
Bytes spectrum_request();                                                                // 05 09
Bytes c_parameter_request(ColourType t);                                                 // BA 09 t
Bytes c_request();                                                                       // 06 09
Bytes density_parameter_request();                                                       // BD 09
Bytes density_request();                                                                 // 03 09
Bytes dmax_request();                                                                    // 04 09
Bytes act_error_request();                                                               // 29

// SpectroScan (D0 ...)
Bytes scan(std::uint8_t scan_opcode, std::span<const std::uint8_t> args = {});
Bytes move_absolute(ScanRef ref, std::uint16_t x_tenth_mm, std::uint16_t y_tenth_mm);  // D0 00
Bytes move_relative(std::int16_t dx_tenth_mm, std::int16_t dy_tenth_mm);               // D0 01
Bytes move_home();                                                                     // D0 02
Bytes move_up();                                                                       // D0 03
Bytes move_down();                                                                     // D0 04
Bytes output_position(ScanRef ref);                                                    // D0 05
Bytes move_to_white(std::uint8_t tile);                                                // D0 06
Bytes move_and_measure(std::uint16_t x_tenth_mm, std::uint16_t y_tenth_mm);            // D0 07
Bytes initialize_device();                                                             // D0 0A
Bytes scan_spectrolino();                                                              // D0 0B
Bytes init_motor_position();                                                           // D0 0C
Bytes set_table_mode(TableMode m);                                                     // D0 0D
Bytes set_light_level(std::uint8_t level);                                             // D0 0E
Bytes set_online();                                                                    // D0 10
Bytes set_offline();                                                                   // D0 11
Bytes hold_paper();                                                                    // D0 12
Bytes release_paper();                                                                 // D0 13
Bytes change_baud(std::uint8_t bt);                                                    // D0 20
Bytes change_handshake(ScanHandshake hs);                                              // D0 21
Bytes output_status();                                                                 // D0 24
Bytes clear_status(std::uint8_t mask);                                                 // D0 25
Bytes set_special_status(std::uint8_t mask);                                           // D0 26
Bytes clear_special_status(std::uint8_t mask);                                         // D0 27
Bytes output_special_status();                                                         // D0 28
Bytes output_type();                                                                   // D0 30
Bytes output_serial();                                                                 // D0 31
Bytes output_part();                                                                   // D0 32
Bytes output_date();                                                                   // D0 33
Bytes output_firmware();                                                               // D0 34
}  // namespace req

// A decoded request header: which table and opcode, and the argument bytes.
struct Request {
  bool scan = false;  // D0 prefix
  std::uint8_t opcode = 0;
  Bytes args;
};
Request parse_request(std::span<const std::uint8_t> body);  // throws protocol_error on an empty body

// ---------------------------------------------------------------- answers

// The answer code of a body: for SpectroScan answers (D1 xx) `scan` is set and `code` is xx.
struct AnswerHead {
  bool scan = false;
  std::uint8_t code = 0;
};
AnswerHead answer_head(std::span<const std::uint8_t> body);

struct DownloadError {  // 1F rem2
  std::uint16_t remote_errors = 0;
  Bytes encode() const;
  static DownloadError decode(std::span<const std::uint8_t> body);
};
struct ExecError {  // 25 err1
  std::uint8_t error = 0;
  Bytes encode() const;
  static ExecError decode(std::span<const std::uint8_t> body);
};
struct ActError {  // 2F err1
  std::uint8_t error = 0;
  Bytes encode() const;
  static ActError decode(std::span<const std::uint8_t> body);
};
struct ComError {  // 26 code
  std::uint8_t error = 0;
  Bytes encode() const;
  static ComError decode(std::span<const std::uint8_t> body);
};
struct ParameterAnswer {  // 0B ds wb il ob filter
  DensityStandard density_standard = DensityStandard::AnsiT;
  WhiteBase white_base = WhiteBase::Absolute;
  Illuminant illuminant = Illuminant::D50;
  Observer observer = Observer::Deg2;
  Filter filter = Filter::None;
  Bytes encode() const;
  static ParameterAnswer decode(std::span<const std::uint8_t> body);
};
struct MeasControlAnswer {  // 5C ctt value rem2
  std::uint8_t ctt = 0;
  std::uint8_t value = 0;
  std::uint16_t remote_errors = 0;
  Bytes encode() const;
  static MeasControlAnswer decode(std::span<const std::uint8_t> body);
};
struct DeviceDataAnswer {  // B6
  std::string name;
  std::uint8_t device_no = kDeviceNoSpectrolino;
  std::string part_no;
  std::uint32_t serial = 0;
  std::string software;
  std::string reserved;
  Bytes encode() const;
  static DeviceDataAnswer decode(std::span<const std::uint8_t> body);
};
struct TargetIdAnswer {  // 31
  std::string name;
  std::uint16_t serial = 0, sw_release = 0, year = 0, month = 0, day = 0, hour = 0, minute = 0;
  std::uint8_t target_tech = kTargetTechSpectrolino;
  std::uint16_t first_wavelength = kFirstWavelength, bands = kSpectrumBands, step = kWavelengthStep;
  Bytes encode() const;
  static TargetIdAnswer decode(std::span<const std::uint8_t> body);
};
struct WhiteReferenceAnswer {  // B4 filter, 36 floats, flag, name[18]
  Filter filter = Filter::None;
  Spectrum reference{};
  std::uint8_t origin = 0;  // 00 factory, 01 user, 02 undefined
  std::string name;
  Bytes encode() const;
  static WhiteReferenceAnswer decode(std::span<const std::uint8_t> body);
};
struct IllumTabAnswer {  // 39 00 il 36 floats rem2
  std::uint8_t illuminant = 0;
  Spectrum table{};
  std::uint16_t remote_errors = 0;
  Bytes encode() const;
  static IllumTabAnswer decode(std::span<const std::uint8_t> body);
};
struct ValNrAnswer {  // 48 60 temp/100 rem2
  std::uint8_t kelvin_over_100 = 0;
  std::uint16_t remote_errors = 0;
  Bytes encode() const;
  static ValNrAnswer decode(std::span<const std::uint8_t> body);
};
struct FloatAnswer {  // C1 type float
  std::uint8_t type = 0;
  float value = 0;
  Bytes encode() const;
  static FloatAnswer decode(std::span<const std::uint8_t> body);
};
struct SlopeAnswer {  // 0C 4 floats
  std::array<float, 4> slope{};
  Bytes encode() const;
  static SlopeAnswer decode(std::span<const std::uint8_t> body);
};
struct NewMeasureAnswer {  // 12 nm 09
  NewMeasurement what = NewMeasurement::None;
  Bytes encode() const;
  static NewMeasureAnswer decode(std::span<const std::uint8_t> body);
};
struct NewKeyAnswer {  // 13 flag key
  std::uint8_t new_key = 0;
  std::uint16_t key = 0;
  Bytes encode() const;
  static NewKeyAnswer decode(std::span<const std::uint8_t> body);
};
struct SpecParameterAnswer {  // B9 09 type 36 floats rv filter wb 02 rem2
  SpectrumType type = SpectrumType::Reflectance;
  Spectrum spectrum{};
  std::uint8_t ref_valid = 1;
  Filter filter = Filter::None;
  WhiteBase white_base = WhiteBase::Absolute;
  std::uint16_t remote_errors = 0;
  Bytes encode() const;
  static SpecParameterAnswer decode(std::span<const std::uint8_t> body);
};
struct SpectrumAnswer {  // 10 09 type 36 floats rv rem2 (also the D0 07 MoveAndMeasure answer)
  SpectrumType type = SpectrumType::Reflectance;
  Spectrum spectrum{};
  std::uint8_t ref_valid = 1;
  std::uint16_t remote_errors = 0;
  Bytes encode() const;
  static SpectrumAnswer decode(std::span<const std::uint8_t> body);
};
struct CParameterAnswer {  // BB 09 type 3 floats rv filter wb 02 il ob rem2
  ColourType type = ColourType::XYZ;
  std::array<float, 3> values{};
  std::uint8_t ref_valid = 1;
  Filter filter = Filter::None;
  WhiteBase white_base = WhiteBase::Absolute;
  Illuminant illuminant = Illuminant::D50;
  Observer observer = Observer::Deg2;
  std::uint16_t remote_errors = 0;
  Bytes encode() const;
  static CParameterAnswer decode(std::span<const std::uint8_t> body);
};
struct CAnswer {  // 11 09 type 3 floats rv rem2
  ColourType type = ColourType::XYZ;
  std::array<float, 3> values{};
  std::uint8_t ref_valid = 1;
  std::uint16_t remote_errors = 0;
  Bytes encode() const;
  static CAnswer decode(std::span<const std::uint8_t> body);
};
struct DensityParameterAnswer {    // BC 09 4 floats sdf rv filter wb 02 ds rem2
  std::array<float, 4> density{};  // Db Dc Dm Dy
  std::uint8_t std_density_filter = 0;
  std::uint8_t ref_valid = 1;
  Filter filter = Filter::None;
  WhiteBase white_base = WhiteBase::Absolute;
  DensityStandard density_standard = DensityStandard::AnsiT;
  std::uint16_t remote_errors = 0;
  Bytes encode() const;
  static DensityParameterAnswer decode(std::span<const std::uint8_t> body);
};
struct DensityAnswer {  // 0E 09 4 floats sdf rv rem2
  std::array<float, 4> density{};
  std::uint8_t std_density_filter = 0;
  std::uint8_t ref_valid = 1;
  std::uint16_t remote_errors = 0;
  Bytes encode() const;
  static DensityAnswer decode(std::span<const std::uint8_t> body);
};
struct DmaxAnswer {  // 0F 09 float λ u16 dmax-ok rv rem2
  float dmax = 0;
  std::uint16_t wavelength = 0;
  std::uint8_t dmax_ok = 1;
  std::uint8_t ref_valid = 1;
  std::uint16_t remote_errors = 0;
  Bytes encode() const;
  static DmaxAnswer decode(std::span<const std::uint8_t> body);
};

// SpectroScan answers (D1 ...)
struct ScanErrorAnswer {  // D1 80 err
  std::uint8_t error = 0;
  Bytes encode() const;
  static ScanErrorAnswer decode(std::span<const std::uint8_t> body);
};
struct ScanComErrorAnswer {  // D1 A0 err
  std::uint8_t error = 0;
  Bytes encode() const;
  static ScanComErrorAnswer decode(std::span<const std::uint8_t> body);
};
struct PositionAnswer {  // D1 81 ref remaining(u16; 0 for OutputActualPosition) x y z
  ScanRef ref = ScanRef::Sensor;
  std::uint16_t remaining = 0;
  std::uint16_t x = 0, y = 0;  // 0.1 mm
  std::uint8_t z = 0;          // 00 up, 01 down
  Bytes encode() const;
  static PositionAnswer decode(std::span<const std::uint8_t> body);
};
struct KeyAnswer {  // D1 82 mask press-time
  std::uint8_t keys = 0;
  std::uint8_t long_press = 0;
  Bytes encode() const;
  static KeyAnswer decode(std::span<const std::uint8_t> body);
};
struct StatusAnswer {  // D1 83 bits
  std::uint8_t bits = 0;
  Bytes encode() const;
  static StatusAnswer decode(std::span<const std::uint8_t> body);
};
struct TypeAnswer {  // D1 90 name[18]
  std::string name;  // "SpectroScan " or "SpectroScanT"
  Bytes encode() const;
  static TypeAnswer decode(std::span<const std::uint8_t> body);
};
struct SerialNumberAnswer {  // D1 91 u32
  std::uint32_t serial = 0;
  Bytes encode() const;
  static SerialNumberAnswer decode(std::span<const std::uint8_t> body);
};
struct ArticleNumberAnswer {  // D1 92 [8]
  std::string part;
  Bytes encode() const;
  static ArticleNumberAnswer decode(std::span<const std::uint8_t> body);
};
struct ProductionDateAnswer {  // D1 93 day month year
  std::uint16_t day = 0, month = 0, year = 0;
  Bytes encode() const;
  static ProductionDateAnswer decode(std::span<const std::uint8_t> body);
};
struct SoftwareVersionAnswer {  // D1 94 [12]
  std::string version;
  Bytes encode() const;
  static SoftwareVersionAnswer decode(std::span<const std::uint8_t> body);
};

}  // namespace colorlab::wire::spectrolino
