// Command dispatch: a request line is unframed (COM errors for a bad frame) and routed to the Spectrolino or,
// behind the D0 prefix, the SpectroScan T command set; answers are framed here.
#include <optional>

#include "colorlab/core/error.hpp"
#include "spectrolino_model_impl.hpp"

namespace colorlab::sim {

namespace sp = wire::spectrolino;

SpectrolinoReply SpectrolinoModel::Impl::answer(const sp::Bytes& body, double seconds) const {
  return SpectrolinoReply{sp::frame_answer(body), seconds, std::nullopt};
}

SpectrolinoReply SpectrolinoModel::Impl::com_error(std::uint8_t code) const {
  return answer(sp::ComError{code}.encode(), timing.command_s);
}

SpectrolinoReply SpectrolinoModel::Impl::scan_error(std::uint8_t code, double seconds) const {
  return answer(sp::ScanErrorAnswer{code}.encode(), seconds);
}

SpectrolinoReply SpectrolinoModel::Impl::handle(std::string_view line) {
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
  if (line.empty() || line.front() != ';') return com_error(sp::com_err::StopButNoStart);
  sp::Bytes body;
  try {
    body = sp::unframe_request(line);
  } catch (const Error&) {
    return com_error(sp::com_err::IllegalCharInRec);
  }
  if (body.empty()) return com_error(sp::com_err::IncorrectRecLen);
  if (body.size() == 1 && body[0] == sp::kScanRequestPrefix) return com_error(sp::com_err::IncorrectRecLen);
  sp::Request r = sp::parse_request(body);
  if (r.scan) return config.table ? spectroscan_command(r) : com_error(sp::com_err::IllegalRecType);
  return spectrolino_command(r);
}

}  // namespace colorlab::sim
