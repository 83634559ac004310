#include "colorlab/bringup/handshake.hpp"

#include <algorithm>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/ls110.hpp"
#include "colorlab/wire/ls110_protocol.hpp"
#include "colorlab/drivers/serial_link.hpp"
#include "colorlab/drivers/spectrolino_link.hpp"
#include "colorlab/wire/enttec_dmx_protocol.hpp"
#include "colorlab/wire/spectrolino_protocol.hpp"

namespace colorlab::bringup {

namespace asio = boost::asio;
namespace sl = colorlab::wire::spectrolino;
namespace en = colorlab::wire::enttec;
using drivers::SerialLink;
using drivers::SerialSettings;
using namespace std::chrono_literals;

namespace {

struct Step {
  std::string kind;
  SerialSettings settings;
  std::string request;
  std::chrono::milliseconds deadline;
  std::string label;
};

// Deadlines: the Spectrolino's from Argyll (0.5 s per speed, instrument-protocols §1.1); the
// widget answers label 10 from its own firmware at once (OLA's detector waits 200 ms per
// request; twice that here); the LS-110 publishes no reply time, and the MDS answer carries
// no measurement, so 1.5 s — a third of PsychoPy's 5 s allowance for a whole MES reading.
std::vector<Step> steps_for(const std::string& kind) {
  if (kind == "dmx") {
    SerialSettings s;
    s.baud = 115200;  // a dummy value for the widget's FTDI VCOM; OLA opens it so
    auto f = en::get_serial_request();
    return {{kind, s, std::string(f.begin(), f.end()), 400ms, "dmx @115200 8N1 (label 10)"}};
  }
  if (kind == "ls110") {
    return {{kind, drivers::Ls110::serial_settings(), wire::ls110::command_set_mode(4), 1500ms, "ls110 @4800 7E2 (MDS,04)"}};
  }
  if (kind == "spectrolino") {
    std::vector<Step> out;
    for (unsigned baud : {9600u, 57600u}) {
      out.push_back({kind, drivers::spectrolino_serial_settings(baud, drivers::FlowControl::none),
                     sl::frame_request(sl::req::output_status()), 500ms,
                     "spectrolino @" + std::to_string(baud) + " 8N1 (;D024)"});
    }
    return out;
  }
  throw Error(ErrorClass::bad_parameter, "no handshake for instrument kind '" + kind + "'",
              "kinds: dmx, ls110, spectrolino");
}

std::vector<std::string> order_of(const HandshakeOptions& o) { return o.order.empty() ? serial_kinds() : o.order; }

std::chrono::milliseconds scaled(std::chrono::milliseconds d, double scale) {
  return std::chrono::milliseconds(static_cast<long long>(static_cast<double>(d.count()) * std::max(scale, 1.0)));
}

Heard recognise_dmx(std::string_view b) {
  for (std::size_t i = 0; i + 4 < b.size(); ++i) {
    if (static_cast<std::uint8_t>(b[i]) != en::kStart) continue;
    std::size_t len = static_cast<std::uint8_t>(b[i + 2]) | (static_cast<std::size_t>(static_cast<std::uint8_t>(b[i + 3])) << 8);
    if (len > en::kMaxPayload || i + 4 + len >= b.size()) continue;
    if (static_cast<std::uint8_t>(b[i + 4 + len]) != en::kEnd) continue;
    return {"dmx", "a widget frame (label " + std::to_string(static_cast<std::uint8_t>(b[i + 1])) + ", " + std::to_string(len) + " bytes)", 0};
  }
  return {};
}

std::vector<std::string> lines_of(std::string_view b) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (b[i] == '\n') {
      out.emplace_back(b.substr(start, i + 1 - start));
      start = i + 1;
    }
  }
  return out;
}

Heard recognise_ls110(std::string_view b) {
  for (auto line : lines_of(b)) {
    for (auto& c : line) c = static_cast<char>(c & 0x7F);  // 7 data bits: a parity bit read as data
    auto at = std::min(line.find("OK"), line.find("ER"));
    if (at == std::string::npos || line.size() < at + 6 || line.substr(line.size() - 2) != "\r\n") continue;
    try {
      auto reply = wire::ls110::parse_reply(std::string_view(line).substr(at));
      return {"ls110", reply.ok ? "OK" + reply.status : reply.error_code, 0};
    } catch (const Error&) {
    }
  }
  return {};
}

Heard recognise_spectrolino(std::string_view b) {
  for (const auto& line : lines_of(b)) {
    auto at = line.find(':');
    if (at == std::string::npos) continue;
    try {
      auto answer = sl::unframe_answer(std::string_view(line).substr(at));
      auto head = sl::answer_head(answer);
      if (head.scan && head.code == sl::scan_ans::StatusAnswer) return {"spectrolino", "a SpectroScan table's status answer (D1 83)", 0};
      if (!head.scan && head.code == sl::ans::ComError) {
        return {"spectrolino", "a stand-alone Spectrolino's COM error answer (26) to the table probe", 0};
      }
      return {"spectrolino", "a Spectrolino-framed answer " + sl::to_hex(answer), 0};
    } catch (const Error&) {
    }
  }
  return {};
}

bool complete_reply(std::string_view b) {
  return !recognise_dmx(b).kind.empty() || !recognise_ls110(b).kind.empty() || !recognise_spectrolino(b).kind.empty();
}

}  // namespace

const std::vector<std::string>& serial_kinds() {
  static const std::vector<std::string> kinds{"dmx", "ls110", "spectrolino"};
  return kinds;
}

bool is_serial_kind(const std::string& kind) {
  return std::find(serial_kinds().begin(), serial_kinds().end(), kind) != serial_kinds().end();
}

std::string instrument_name(const std::string& kind) {
  if (kind == "dmx") return "the Enttec DMX USB Pro";
  if (kind == "ls110") return "the Konica Minolta LS-110";
  if (kind == "spectrolino") return "the Spectrolino / SpectroScan";
  throw Error(ErrorClass::bad_parameter, "unknown instrument kind '" + kind + "'", "kinds: dmx, ls110, spectrolino");
}

Heard recognise(std::string_view bytes) {
  if (auto h = recognise_dmx(bytes); !h.kind.empty()) return h;
  if (auto h = recognise_spectrolino(bytes); !h.kind.empty()) return h;
  return recognise_ls110(bytes);
}

std::chrono::milliseconds handshake_budget(const HandshakeOptions& options) {
  std::chrono::milliseconds total{0};
  for (const auto& kind : order_of(options)) {
    for (const auto& s : steps_for(kind)) total += scaled(s.deadline, options.deadline_scale);
  }
  return total;
}

asio::awaitable<HandshakeResult> handshake(asio::any_io_executor executor, std::string port, HandshakeOptions options,
                                           Recording& recording) {
  HandshakeResult result;
  SerialLink link(executor, port);
  recording.attach(link.transcript());
  struct Detach {
    SerialLink& l;
    ~Detach() { Recording::detach(l.transcript()); }
  } detach{link};
  for (const auto& kind : order_of(options)) {
    for (const auto& step : steps_for(kind)) {
      result.tried.push_back(step.label);
      recording.mark("handshake: " + step.label);
      try {
        if (link.is_open()) {
          link.reconfigure(step.settings);
        } else {
          link.open(step.settings);
        }
      } catch (const Error& e) {
        result.open_error = e.info().message;
        result.open_hint = e.hint();
        co_return result;
      }
      link.discard_input();
      auto deadline = scaled(step.deadline, options.deadline_scale);
      std::string got;
      try {
        co_await link.write(step.request, deadline);
        auto until = std::chrono::steady_clock::now() + deadline;
        // Byte by byte from the link's buffer, so a reply counts the moment it is complete.
        while (!complete_reply(got) && got.size() < 4096) {
          auto left = until - std::chrono::steady_clock::now();
          if (left <= SerialLink::Duration::zero()) break;
          got += co_await link.read_exactly(1, left);
        }
      } catch (const Error& e) {
        if (e.cls() != ErrorClass::timeout) {
          result.open_error = e.info().message;
          result.open_hint = e.hint();
          co_return result;
        }
      }
      auto heard = recognise(got);
      if (!heard.kind.empty()) {
        heard.baud = step.settings.baud;
        result.heard = heard;
        co_return result;
      }
      result.garbage += got;
    }
  }
  co_return result;
}

}  // namespace colorlab::bringup
