#include "colorlab/drivers/port_enumeration.hpp"

#include <libserialport.h>

namespace colorlab::drivers {

namespace {
std::string str(const char* s) { return s ? s : ""; }
}  // namespace

std::vector<SerialPortInfo> enumerate_serial_ports() {
  std::vector<SerialPortInfo> out;
  sp_port** ports = nullptr;
  if (sp_list_ports(&ports) != SP_OK) return out;
  for (sp_port** p = ports; *p; ++p) {
    SerialPortInfo info;
    info.path = str(sp_get_port_name(*p));
    info.description = str(sp_get_port_description(*p));
    switch (sp_get_port_transport(*p)) {
      case SP_TRANSPORT_USB: {
        info.transport = "usb";
        int vid = 0, pid = 0;
        if (sp_get_port_usb_vid_pid(*p, &vid, &pid) == SP_OK) {
          info.usb_vid = vid;
          info.usb_pid = pid;
        }
        info.usb_serial = str(sp_get_port_usb_serial(*p));
        info.usb_manufacturer = str(sp_get_port_usb_manufacturer(*p));
        info.usb_product = str(sp_get_port_usb_product(*p));
        break;
      }
      case SP_TRANSPORT_BLUETOOTH: info.transport = "bluetooth"; break;
      default: info.transport = "native"; break;
    }
    out.push_back(std::move(info));
  }
  sp_free_port_list(ports);
  return out;
}

}  // namespace colorlab::drivers
