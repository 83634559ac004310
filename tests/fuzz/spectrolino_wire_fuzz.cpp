// The Spectrolino/SpectroScan hex protocol (drivers/wire): one line off the serial port, as the
// driver reads an answer (':' hex CR LF → every answer decoder) and as the simulated instrument
// reads a request (';' hex CR LF → parse_request).
#include "colorlab/wire/spectrolino_protocol.hpp"
#include "fuzz_support.hpp"

namespace {

namespace sp = colorlab::wire::spectrolino;
using colorlab::fuzz::typed;

template <class Answer>
void decode(const char* what, std::span<const std::uint8_t> body, void (*then)(const Answer&) = nullptr) {
  typed(what, [&] {
    Answer a = Answer::decode(body);
    (void)a.encode();
    if (then) then(a);
  });
}

void answers(std::span<const std::uint8_t> body) {
  if (!typed("answer_head", [&] { (void)sp::answer_head(body); })) return;
  decode<sp::DownloadError>("DownloadError", body);
  // The driver turns an error answer's code into a typed error through the error tables.
  decode<sp::ExecError>("ExecError", body, [](const sp::ExecError& e) {
    typed("throw_on_exec_error", [&] { sp::throw_on_exec_error(e.error, "fuzz", {0x13, 0x34}); });
  });
  decode<sp::ActError>("ActError", body);
  decode<sp::ComError>("ComError", body);
  decode<sp::ParameterAnswer>("ParameterAnswer", body);
  decode<sp::MeasControlAnswer>("MeasControlAnswer", body);
  decode<sp::DeviceDataAnswer>("DeviceDataAnswer", body);
  decode<sp::TargetIdAnswer>("TargetIdAnswer", body);
  decode<sp::WhiteReferenceAnswer>("WhiteReferenceAnswer", body);
  decode<sp::IllumTabAnswer>("IllumTabAnswer", body);
  decode<sp::ValNrAnswer>("ValNrAnswer", body);
  decode<sp::FloatAnswer>("FloatAnswer", body);
  decode<sp::SlopeAnswer>("SlopeAnswer", body);
  decode<sp::NewMeasureAnswer>("NewMeasureAnswer", body);
  decode<sp::NewKeyAnswer>("NewKeyAnswer", body);
  decode<sp::SpecParameterAnswer>("SpecParameterAnswer", body);
  decode<sp::SpectrumAnswer>("SpectrumAnswer", body);
  decode<sp::CParameterAnswer>("CParameterAnswer", body);
  decode<sp::CAnswer>("CAnswer", body);
  decode<sp::DensityParameterAnswer>("DensityParameterAnswer", body);
  decode<sp::DensityAnswer>("DensityAnswer", body);
  decode<sp::DmaxAnswer>("DmaxAnswer", body);
  decode<sp::ScanErrorAnswer>("ScanErrorAnswer", body, [](const sp::ScanErrorAnswer& e) {
    typed("throw_on_scan_error", [&] { sp::throw_on_scan_error(e.error, "fuzz"); });
  });
  decode<sp::ScanComErrorAnswer>("ScanComErrorAnswer", body);
  decode<sp::PositionAnswer>("PositionAnswer", body);
  decode<sp::KeyAnswer>("KeyAnswer", body);
  decode<sp::StatusAnswer>("StatusAnswer", body);
  decode<sp::TypeAnswer>("TypeAnswer", body);
  decode<sp::SerialNumberAnswer>("SerialNumberAnswer", body);
  decode<sp::ArticleNumberAnswer>("ArticleNumberAnswer", body);
  decode<sp::ProductionDateAnswer>("ProductionDateAnswer", body);
  decode<sp::SoftwareVersionAnswer>("SoftwareVersionAnswer", body);
  if (body.size() >= 3) {
    std::uint16_t remote = static_cast<std::uint16_t>(body[body.size() - 2] | body[body.size() - 1] << 8);
    (void)sp::describe_remote_errors(remote);
    typed("throw_on_remote_error", [&] { sp::throw_on_remote_error(remote, "fuzz"); });
  }
}

void one_input(const std::uint8_t* data, std::size_t size) {
  const auto line = colorlab::fuzz::as_text(data, size);
  sp::Bytes body;
  if (typed("unframe_answer", [&] { body = sp::unframe_answer(line); })) answers(body);
  if (typed("unframe_request", [&] { body = sp::unframe_request(line); })) {
    typed("parse_request", [&] { (void)sp::parse_request(body); });
  }
}

}  // namespace

COLORLAB_FUZZ_TARGET("spectrolino_wire", one_input)
