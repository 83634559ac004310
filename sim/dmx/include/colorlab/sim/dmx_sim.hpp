#pragma once
// The simulated Enttec DMX USB Pro on a pty (instrument-protocols.md §3a). Label 6 packets drive the
// Scene's lamps and dimmer through a channel map; labels 3/4/10 behave like a genuine widget (no answer
// to OLA's 77/78 extensions). The widget is an FTDI VCOM, so any baud rate the client sets is accepted.
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colorlab/sim/link_faults.hpp"
#include "colorlab/sim/pty_device.hpp"
#include "colorlab/wire/enttec_dmx_protocol.hpp"

namespace colorlab::sim {

class Scene;

struct DmxChannelMapping {
  int channel = 1;     // DMX slot, 1-based
  std::string target;  // a lamp name (D65, TL84, CWF, A, UV: on at >= 128) or "dimmer" (0..255 -> 0..100 %)
};

struct DmxConfig {
  std::uint32_t serial_decimal = 12345678;  // printed on the widget; sent as BCD
  std::vector<DmxChannelMapping> channels{{1, "D65"}, {2, "TL84"}, {3, "CWF"}, {4, "A"}, {5, "UV"}, {6, "dimmer"}};
};
// Throws Error{bad_parameter} for a channel outside 1..512, an unknown target or a channel used twice.
void validate(const DmxConfig& config);

class DmxSim final : public PtyDevice {
 public:
  DmxSim(boost::asio::any_io_executor executor, Scene& scene, DmxConfig config, std::uint64_t seed, double time_scale);

  void set_faults(const LinkFaults& faults);
  const LinkFaults& faults() const { return faults_; }

  const std::vector<std::uint8_t>& universe() const { return universe_; }  // last label-6 slots
  const wire::enttec::WidgetParameters& parameters() const { return params_; }
  std::uint64_t packets() const { return packets_; }
  std::size_t bad_frames() const { return parser_.bad_frames(); }
  std::size_t rejected_requests() const { return rejected_; }
  const DmxConfig& config() const { return config_; }

  static constexpr double kReplySeconds = 0.001;  // widget firmware turnaround

 private:
  void on_bytes(std::string_view bytes) override;
  void handle(const wire::enttec::Frame& f);
  void apply_universe(const std::vector<std::uint8_t>& previous);
  void send(std::vector<std::uint8_t> frame, std::size_t request_bytes);
  bool link_down() const;

  Scene& scene_;
  DmxConfig config_;
  wire::enttec::FrameParser parser_;
  wire::enttec::WidgetParameters params_;
  std::vector<std::uint8_t> universe_;
  LinkFaults faults_;
  double silent_until_ = -1;
  std::mt19937_64 rng_;
  std::uint64_t packets_ = 0;
  std::size_t rejected_ = 0;
};

}  // namespace colorlab::sim
