#pragma once
// Real serial ports with their USB identity, so config can name an instrument by VID/PID/serial
// instead of a /dev/ttyUSBn that changes with plug order. Pseudo-terminals never appear here.
#include <optional>
#include <string>
#include <vector>

namespace colorlab::drivers {

struct SerialPortInfo {
  std::string path;  // /dev/ttyUSB0
  std::string description;
  std::string transport;  // native, usb, bluetooth
  std::optional<int> usb_vid;
  std::optional<int> usb_pid;
  std::string usb_serial;
  std::string usb_manufacturer;
  std::string usb_product;
};

std::vector<SerialPortInfo> enumerate_serial_ports();

}  // namespace colorlab::drivers
