#pragma once
// GretagMacbeth Spectrolino, stand-alone or docked in a SpectroScan / SpectroScan T table.
// connect(): baud scan with no flow control, then both ends move to the fastest common speed
// (57600) with RTS/CTS, identity is verified (B5, 2B, D0 30 …) and the colorimetric parameters set.
// XYZ comes from colorlab's own colorimetry of the spectrum, not from a second instrument query.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/any_io_executor.hpp>

#include "colorlab/drivers/lab_capabilities.hpp"
#include "colorlab/drivers/reconnect.hpp"
#include "colorlab/drivers/serpentine.hpp"
#include "colorlab/drivers/spectrolino_link.hpp"

namespace colorlab::analysis {
class ReflectanceIntegrator;
}

namespace colorlab::drivers {

struct SpectrolinoOptions {
  std::string id = "spectrolino";
  std::string port;
  bool simulated = false;
  unsigned max_baud = 57600;     // the highest speed both Spectrolino and SpectroScan offer
  bool initialise_table = true;  // D0 0A InitializeDevice at connect (homes the motors)
  sl::Illuminant illuminant = sl::Illuminant::D50;
  sl::Observer observer = sl::Observer::Deg2;
  sl::WhiteBase white_base = sl::WhiteBase::Absolute;
  sl::DensityStandard density_standard = sl::DensityStandard::AnsiT;
  std::uint8_t white_tile = 0;       // SpectroScan tile 1
  int reflective_cal_interval = 50;  // readings between white calibrations (Argyll SS_REF_CAL_COUNT)
  int transmissive_cal_interval = 10;
  int command_attempts = 3;  // per exchange, for timeouts, garbled lines and COM errors
  int patch_attempts = 5;    // per chart patch, with a recalibration after each failure
  SpectrolinoTimeouts timeouts;
  ReconnectPolicy reconnect;
};

struct TableStatus {
  bool online = false;
  bool paper_held = false;
  bool enter_pressed = false;
  bool digitizing = false;
  bool key_ack = false;
};

class Spectrolino final : public Spectrometer, public XyTable {
 public:
  Spectrolino(boost::asio::any_io_executor executor, SpectrolinoOptions options);
  ~Spectrolino() override;

  const std::string& id() const override { return options_.id; }
  Identity identity() const override;
  InstrumentState state() const override { return state_; }
  std::vector<Capability> capabilities() const override;
  std::vector<CalibrationStatus> calibration() const override;
  std::string last_problem() const override { return last_problem_; }

  boost::asio::awaitable<void> connect() override;
  void disconnect() override;

  // Spectrometer
  boost::asio::awaitable<void> set_mode(SpectralMode mode) override;
  boost::asio::awaitable<void> calibrate() override;
  boost::asio::awaitable<SpectralReading> measure() override;
  boost::asio::awaitable<void> set_colorimetry(sl::Illuminant il, sl::Observer ob, sl::WhiteBase wb);

  // XyTable (SpectroScan only; Error{unsupported} on a stand-alone Spectrolino)
  // The SpectroScan T's measuring area (instrument-protocols.md: positions in 0.1 mm up to 310 × 230 mm).
  static constexpr TableTravel kTravel{310.0, 230.0};
  std::optional<TableTravel> travel() const override { return kTravel; }
  boost::asio::awaitable<void> move_to(double x_mm, double y_mm) override;
  boost::asio::awaitable<void> home() override;
  boost::asio::awaitable<void> head_up() override;
  boost::asio::awaitable<void> head_down() override;
  boost::asio::awaitable<void> hold_paper(bool hold) override;
  boost::asio::awaitable<TablePosition> position() override;
  boost::asio::awaitable<SpectralReading> move_and_measure(double x_mm, double y_mm) override;
  boost::asio::awaitable<SpectralReading> read_chart_patch(const ChartPatchVisit& visit) override;
  boost::asio::awaitable<TableStatus> table_status();

  // Reads every patch in serpentine order; returns readings in the chart's own patch order.
  // `progress(done, total)` is called after each patch.
  using Progress = std::function<void(int done, int total)>;
  boost::asio::awaitable<std::vector<SpectralReading>> read_chart(const ChartLayout& layout, Progress progress = {});

  SpectrolinoTopology topology() const { return topology_; }
  unsigned baud() const;
  SpectralMode mode() const { return mode_; }
  int readings_since_calibration() const { return readings_since_cal_; }
  int calibrations_done() const { return calibrations_; }
  std::uint64_t commands_sent() const { return protocol_.commands_sent(); }
  Transcript& transcript() { return link_.transcript(); }

 private:
  boost::asio::awaitable<void> calibrate_now();
  boost::asio::awaitable<void> negotiate_standalone(unsigned found_baud);
  boost::asio::awaitable<void> negotiate_table(unsigned found_baud);
  boost::asio::awaitable<void> identify();
  boost::asio::awaitable<void> apply_parameters();
  boost::asio::awaitable<void> scan_command(const sl::Bytes& body, std::chrono::milliseconds timeout, std::string_view what);
  boost::asio::awaitable<void> table_command(sl::Bytes body, std::chrono::milliseconds timeout, std::string_view what);
  boost::asio::awaitable<void> download(const sl::Bytes& body, std::string_view what);
  boost::asio::awaitable<SpectralReading> read_spectrum_after_exec();
  boost::asio::awaitable<SpectralReading> measure_patch(const PatchVisit& patch);
  SpectralReading make_reading(const sl::Spectrum& spectrum);
  void require_table(std::string_view what) const;
  void verify_serial(const std::string& expected) const;
  void require_ready(std::string_view what);
  int cal_interval() const;
  [[noreturn]] void fail(const Error& e);

  SpectrolinoOptions options_;
  boost::asio::any_io_executor executor_;
  SerialLink link_;
  SpectrolinoLink protocol_;
  Reconnector reconnector_;
  InstrumentState state_ = InstrumentState::disconnected;
  std::string last_problem_;
  SpectrolinoTopology topology_ = SpectrolinoTopology::standalone;
  SpectralMode mode_ = SpectralMode::reflectance;
  Identity identity_;
  bool calibrated_ = false;
  int readings_since_cal_ = 0;
  int calibrations_ = 0;
  std::shared_ptr<analysis::ReflectanceIntegrator> integrator_;
  bool integrator_failed_ = false;
};

}  // namespace colorlab::drivers
