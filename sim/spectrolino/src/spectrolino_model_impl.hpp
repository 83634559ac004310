#pragma once
// SpectrolinoModel's state, one part per job, and where each job's code lives. Private to sim/spectrolino.
//   spectrolino_model.cpp     construction, power-on state, the public accessors
//   command_dispatch.cpp      request lines: unframing, COM errors, routing to a command set; answer framing
//   spectrolino_commands.cpp  the Spectrolino command set (settings, white reference, measure, results)
//   spectroscan_commands.cpp  the SpectroScan T command set (D0 ...)
//   table_kinematics.*        the table: position, moves and their timing, head up/down, paper hold, status
//   calibration.*             white reference, white/emission calibration and its validity
//   device_state.*            settings the host sets, the Error Type state and the new-measurement flag
//   measurement.*             what the optics see: the surface or light under the head, noise, the last spectrum
//   colorimetry.*             XYZ/xyY/Lab/LCh/Luv of the last spectrum, illuminant tables
//   densitometry.*            spectrum types, status densities and Dmax, the density filter table
#include <cstdint>
#include <random>
#include <string_view>

#include "calibration.hpp"
#include "colorimetry.hpp"
#include "colorlab/sim/spectrolino_model.hpp"
#include "device_state.hpp"
#include "measurement.hpp"
#include "table_kinematics.hpp"

namespace colorlab::sim {

struct SpectrolinoModel::Impl {
  Impl(const Scene& scene, SpectrolinoConfig config, std::uint64_t seed);

  const Scene& scene;
  SpectrolinoConfig config;
  SpectrolinoTiming timing;
  std::mt19937_64 rng;

  spectrolino_detail::DeviceSettings settings;
  spectrolino_detail::ErrorState errors;
  spectrolino_detail::WhiteCalibration cal;
  spectrolino_detail::ScanTable table;
  spectrolino_detail::LastMeasurement last;
  spectrolino_detail::Colorimetry colorimetry;

  void power_cycle();  // spectrolino_model.cpp

  // command_dispatch.cpp
  SpectrolinoReply handle(std::string_view line);
  SpectrolinoReply answer(const wire::spectrolino::Bytes& body, double seconds) const;
  SpectrolinoReply com_error(std::uint8_t code) const;
  SpectrolinoReply scan_error(std::uint8_t code, double seconds) const;

  SpectrolinoReply spectrolino_command(const wire::spectrolino::Request& r);  // spectrolino_commands.cpp
  SpectrolinoReply spectroscan_command(const wire::spectrolino::Request& r);  // spectroscan_commands.cpp

  // measurement.cpp
  wire::spectrolino::Spectrum target_spectrum() const;      // truth for the current mode and place
  wire::spectrolino::Spectrum surface_reflectance() const;  // whatever the mode or head state
  wire::spectrolino::Spectrum raw_under_head();             // what the optics see now, before calibration
  std::uint8_t measure(double& seconds);                    // ExecMeasurement: returns the Error Type

  // calibration.cpp
  bool calibration_valid() const;
  std::uint8_t reference_measure(std::uint8_t mode, double& seconds);  // ExecRefMeasurement
};

}  // namespace colorlab::sim
