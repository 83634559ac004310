#pragma once
// Cabinet lamps and dimmer on an Enttec DMX USB Pro (FTDI virtual serial port). Discovery asks for
// the widget serial (label 10, the only request a genuine widget must answer) and its parameters
// (label 3); output is label 6 with the start code. Level changes ramp at a configured rate and
// return after a configured settle time, so a campaign measures only once the light is steady.
#include <chrono>
#include <map>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>

#include "colorlab/drivers/lab_capabilities.hpp"
#include "colorlab/drivers/lamp_map.hpp"
#include "colorlab/drivers/reconnect.hpp"
#include "colorlab/drivers/serial_link.hpp"
#include "colorlab/wire/enttec_dmx_protocol.hpp"

namespace colorlab::drivers {

struct EnttecDmxOptions {
  std::string id = "dmx";
  std::string port;
  bool simulated = false;
  LampMap lamps;                                 // lamp name → DMX channel (1..512)
  int dimmer_channel = 0;                        // 0 = no dimmer channel; its level scales nothing else
  double ramp_per_second = 0;                    // level change per second (1.0 = 0→full in 1 s); 0 = step
  std::chrono::milliseconds settle{0};           // wait after the last ramp step
  std::chrono::milliseconds frame_interval{25};  // ramp step spacing (40 packets/s, the widget's maximum rate)
  std::chrono::milliseconds reply_timeout{1000};
  int attempts = 3;
  std::size_t slots = 512;  // full universes: some widgets ignore short frames
  ReconnectPolicy reconnect;
};

class EnttecDmx final : public LampController, public Dimmer {
 public:
  EnttecDmx(boost::asio::any_io_executor executor, EnttecDmxOptions options);

  const std::string& id() const override { return options_.id; }
  Identity identity() const override;
  InstrumentState state() const override { return state_; }
  std::vector<Capability> capabilities() const override { return {Capability::lamp_switching, Capability::dimmer}; }
  std::string last_problem() const override { return last_problem_; }

  boost::asio::awaitable<void> connect() override;
  void disconnect() override;

  std::vector<std::string> lamp_names() const override;
  boost::asio::awaitable<void> set_lamps(std::vector<std::string> on) override;
  std::vector<std::string> lamps_on() const override;
  // `lamp` is a lamp name or "dimmer" (the dimmer channel).
  boost::asio::awaitable<void> set_level(const std::string& lamp, double level) override;
  double level(const std::string& lamp) const override;

  const std::vector<std::uint8_t>& universe() const { return universe_; }
  std::uint32_t widget_serial() const { return serial_; }
  std::uint16_t firmware() const { return params_.firmware; }
  std::uint64_t packets_sent() const { return packets_; }
  Transcript& transcript() { return link_.transcript(); }

 private:
  boost::asio::awaitable<wire::enttec::Frame> request(const wire::enttec::Bytes& frame, std::uint8_t reply_label,
                                                      std::string_view what);
  boost::asio::awaitable<wire::enttec::Frame> read_frame(std::chrono::steady_clock::time_point deadline);
  boost::asio::awaitable<void> send_universe();
  // Ramps the given channels to their targets together, then settles.
  boost::asio::awaitable<void> ramp_to(const std::map<int, std::uint8_t>& targets);
  boost::asio::awaitable<void> ramp_with_reconnect(const std::map<int, std::uint8_t>& targets);
  int channel_of(const std::string& lamp) const;
  [[noreturn]] void fail(const Error& e);

  EnttecDmxOptions options_;
  boost::asio::any_io_executor executor_;
  SerialLink link_;
  Reconnector reconnector_;
  InstrumentState state_ = InstrumentState::disconnected;
  std::string last_problem_;
  std::vector<std::uint8_t> universe_;
  std::uint32_t serial_ = 0;
  wire::enttec::WidgetParameters params_;
  std::uint64_t packets_ = 0;
};

}  // namespace colorlab::drivers
