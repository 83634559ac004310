#include "colorlab/sim/aravis/gv_fake_camera.hpp"

#include <arpa/inet.h>
#include <arv.h>
#include <fcntl.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>

#include "colorlab/core/error.hpp"

namespace colorlab::sim::aravis {

namespace {

// GenICam PFNC codes of the formats we add (12/16-bit samples in 16-bit little-endian containers).
constexpr std::uint32_t kBayerRG12 = 0x01100011;
constexpr std::uint32_t kBayerRG16 = 0x0110002F;
constexpr std::uint32_t kMono16 = 0x01100007;

std::string_view format_name(std::uint32_t pf) {
  switch (pf) {
    case kBayerRG12: return "BayerRG12";
    case kBayerRG16: return "BayerRG16";
    case kMono16: return "Mono16";
    default: return {};
  }
}

// Aravis binds the fake to an interface found by its address (or name), so an address that is merely routed to
// loopback (127.0.0.2 on a stock Linux) does not serve; say so before Aravis fails with a bare "could not start".
// A name such as "lo" is left to Aravis.
bool is_ipv4_without_interface(const std::string& address) {
  in_addr wanted{};
  if (::inet_pton(AF_INET, address.c_str(), &wanted) != 1) return false;
  ifaddrs* list = nullptr;
  if (::getifaddrs(&list) != 0) return false;
  bool found = false;
  for (auto* i = list; i && !found; i = i->ifa_next) {
    if (i->ifa_addr && i->ifa_addr->sa_family == AF_INET) {
      found = reinterpret_cast<const sockaddr_in*>(i->ifa_addr)->sin_addr.s_addr == wanted.s_addr;
    }
  }
  ::freeifaddrs(list);
  return !found;
}

}  // namespace

std::uint16_t test_pattern_value(int x, int y) {
  const int cell = (y & 1) * 2 + (x & 1);
  return static_cast<std::uint16_t>(1000 * cell + (x + 3 * y) % 997);
}

std::string GvFakeCamera::genicam_xml() {
  ArvFakeCamera* probe = arv_fake_camera_new("xmlprobe");
  size_t size = 0;
  const char* xml = arv_fake_camera_get_genicam_xml(probe, &size);
  std::string text(xml ? xml : "", xml ? size : 0);
  g_object_unref(probe);
  const std::string anchor = "<pValue>PixelFormatRegister</pValue>";
  const auto at = text.find(anchor);
  if (at == std::string::npos) {
    throw Error(ErrorClass::internal, "Aravis's fake-camera GenICam XML has no PixelFormatRegister",
                "this Aravis version differs from 0.8.26; update sim/aravis to its XML");
  }
  char entries[512];
  std::snprintf(entries, sizeof entries,
                "<EnumEntry Name=\"BayerRG12\" NameSpace=\"Standard\"><Value>%u</Value></EnumEntry>\n"
                "\t\t<EnumEntry Name=\"BayerRG16\" NameSpace=\"Standard\"><Value>%u</Value></EnumEntry>\n\t\t",
                kBayerRG12, kBayerRG16);
  text.insert(at, entries);
  return text;
}

struct GvFakeCamera::Impl {
  GvFakeOptions options;
  std::filesystem::path xml_file;
  ArvGvFakeCamera* gv = nullptr;
  ArvFakeCamera* fake = nullptr;
  std::atomic<std::uint64_t> frames{0};
  int lock_fd = -1;

  void start();  // (re)creates the GigE Vision server with the current options

  static void fill(ArvBuffer* buffer, void* self, guint32 exposure_us, guint32 gain, ArvPixelFormat pf) {
    auto* impl = static_cast<Impl*>(self);
    size_t reported = 0;
    // Aravis reports 0 bytes here (the fake zeroes received_size before the fill) although the
    // buffer holds a whole payload, so the size is computed from the region instead.
    auto* data = static_cast<std::uint16_t*>(const_cast<void*>(arv_buffer_get_data(buffer, &reported)));
    gint x = 0, y = 0, w = 0, h = 0;
    arv_buffer_get_image_region(buffer, &x, &y, &w, &h);
    const std::string_view name = format_name(pf);
    if (!data || w <= 0 || h <= 0 || name.empty()) return;  // 8-bit formats keep Aravis's zeros
    std::span<std::uint16_t> out(data, static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
    FillRequest req{x, y, w, h, name, static_cast<double>(exposure_us), static_cast<double>(gain),
                    arv_buffer_get_frame_id(buffer)};
    if (impl->options.fill) {
      try {
        impl->options.fill(req, out);
      } catch (...) {
        std::fill(out.begin(), out.end(), 0);  // never let an exception unwind through Aravis's C thread
      }
    } else {
      for (int r = 0; r < h; ++r) {
        for (int c = 0; c < w; ++c) out[static_cast<std::size_t>(r * w + c)] = test_pattern_value(x + c, y + r);
      }
    }
    impl->frames.fetch_add(1);
  }

  ~Impl() {
    if (gv) g_object_unref(gv);
    if (lock_fd >= 0) ::close(lock_fd);  // releases the address for the next fake
    std::error_code ec;
    if (!xml_file.empty()) std::filesystem::remove(xml_file, ec);
  }
};

GvFakeCamera::GvFakeCamera(GvFakeOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
  auto& o = impl_->options;
  if (o.serial.empty() || o.serial.size() > 15) {
    throw Error(ErrorClass::bad_parameter, "GigE Vision serial '" + o.serial + "' must have 1..15 characters",
                "shorten the serial in the simulator config");
  }
  if (is_ipv4_without_interface(o.address)) {
    throw Error(ErrorClass::bad_parameter,
                "no network interface has the address " + o.address + " for the GigE Vision fake camera",
                "give loopback the address first (as root: ip addr add " + o.address +
                    "/8 dev lo), run the lab in its own network namespace, or use an address this machine has");
  }
  // The fake's sockets use SO_REUSEADDR, so a second fake on the same address would start
  // "successfully" and clients would talk to either. A lock file per address, held for the
  // fake's lifetime (and dropped by the kernel if the process dies), makes the second one fail.
  const auto lock_path = std::filesystem::temp_directory_path() / ("colorlab-gvfake-" + o.address + ".lock");
  impl_->lock_fd = ::open(lock_path.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0666);
  if (impl_->lock_fd < 0 || ::flock(impl_->lock_fd, LOCK_EX | LOCK_NB) != 0) {
    throw Error(ErrorClass::conflict,
                "another GigE Vision fake camera is serving " + o.address + " (lock " + lock_path.string() + ")",
                "stop the other simulated GenICam camera (another colorlab-sim or a test) and retry");
  }
  impl_->xml_file = std::filesystem::temp_directory_path() /
                    ("colorlab-gvfake-" + std::to_string(::getpid()) + "-" + o.address + ".xml");
  {
    std::ofstream xml(impl_->xml_file);
    xml << genicam_xml();
    if (!xml) throw Error(ErrorClass::io_error, "cannot write " + impl_->xml_file.string(), "check /tmp");
  }
  impl_->start();
}

void GvFakeCamera::Impl::start() {
  const auto& o = options;
  gv = arv_gv_fake_camera_new_full(o.address.c_str(), o.serial.c_str(), xml_file.c_str());
  if (!gv || !arv_gv_fake_camera_is_running(gv)) {
    if (gv) g_object_unref(gv);
    gv = nullptr;
    throw Error(ErrorClass::conflict,
                "GigE Vision fake camera could not start on " + o.address + " (GVCP port 3956 in use?)",
                "stop the other simulated GenICam camera (another colorlab-sim or a test) and retry");
  }
  fake = arv_gv_fake_camera_get_fake_camera(gv);
  arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_SENSOR_WIDTH, static_cast<guint32>(o.sensor_width));
  arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_SENSOR_HEIGHT, static_cast<guint32>(o.sensor_height));
  arv_fake_camera_set_fill_pattern(fake, &Impl::fill, this);
}

void GvFakeCamera::unplug() {
  if (!impl_->gv) return;
  g_object_unref(impl_->gv);
  impl_->gv = nullptr;
  impl_->fake = nullptr;
}

void GvFakeCamera::plug_in(std::optional<std::string> serial) {
  unplug();
  if (serial) {
    if (serial->empty() || serial->size() > 15) {
      throw Error(ErrorClass::bad_parameter, "GigE Vision serial '" + *serial + "' must have 1..15 characters",
                  "shorten the serial");
    }
    impl_->options.serial = *serial;
  }
  impl_->start();
}

bool GvFakeCamera::plugged_in() const { return impl_->gv != nullptr; }

GvFakeCamera::~GvFakeCamera() = default;

const std::string& GvFakeCamera::address() const { return impl_->options.address; }
const std::string& GvFakeCamera::serial() const { return impl_->options.serial; }
std::uint64_t GvFakeCamera::frames_filled() const { return impl_->frames.load(); }

void GvFakeCamera::stall() {
  if (impl_->fake) arv_fake_camera_write_register(impl_->fake, ARV_FAKE_CAMERA_REGISTER_ACQUISITION, 0);
}

}  // namespace colorlab::sim::aravis
