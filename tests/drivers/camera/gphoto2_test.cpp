// The libgphoto2 driver's camera-free parts: the model table, error mapping, and card access
// through libgphoto2's "Directory Browse" camlib on a temporary directory (disk: port).
#include <gphoto2/gphoto2-port-result.h>
#include <gphoto2/gphoto2-result.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include "colorlab/drivers/camera/gphoto2_camera.hpp"
#include "colorlab/drivers/camera/raw_decoder.hpp"
#include "colorlab/sim/camera/dng.hpp"
#include "sim_fixture.hpp"

namespace cam = colorlab::drivers::camera;
namespace fs = std::filesystem;
using colorlab::ErrorClass;

TEST(camera_gphoto2, eos20d_normal_mode_captures_and_configures_through_canon_camlib) {
  const auto a = cam::gphoto2_abilities("Canon EOS 20D (normal mode)");
  EXPECT_EQ(a.model, "Canon EOS 20D (normal mode)");
  EXPECT_TRUE(a.capture_image);
  EXPECT_TRUE(a.config);
  // The camlib's CAP_EXP flag only gates capture inside the canon camlib; the driver status
  // libgphoto2 publishes for the model is "production".
  EXPECT_FALSE(a.experimental);
  EXPECT_EQ(a.usb_vendor, 0x04a9);
  EXPECT_EQ(a.usb_product, 0x30eb);
  EXPECT_NE(a.library.find("canon"), std::string::npos) << a.library;
}

TEST(camera_gphoto2, eos20d_ptp_mode_cannot_capture) {
  const auto a = cam::gphoto2_abilities("Canon EOS 20D (PTP mode)");
  EXPECT_FALSE(a.capture_image);
  EXPECT_NE(a.library.find("ptp2"), std::string::npos) << a.library;
}

TEST(camera_gphoto2, unknown_model_is_not_found) {
  try {
    cam::gphoto2_abilities("Canon EOS 99Z (imaginary)");
    FAIL();
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::not_found);
    EXPECT_NE(e.hint().find("list-cameras"), std::string::npos);
  }
}

TEST(camera_gphoto2, result_codes_map_to_error_classes) {
  const std::pair<int, ErrorClass> table[] = {
      {GP_ERROR_TIMEOUT, ErrorClass::timeout},
      {GP_ERROR_CAMERA_BUSY, ErrorClass::conflict},
      {GP_ERROR_IO_USB_CLAIM, ErrorClass::conflict},
      {GP_ERROR_NOT_SUPPORTED, ErrorClass::unsupported},
      {GP_ERROR_BAD_PARAMETERS, ErrorClass::bad_parameter},
      {GP_ERROR_IO, ErrorClass::no_comms},
      {GP_ERROR_IO_READ, ErrorClass::no_comms},
      {GP_ERROR_IO_USB_FIND, ErrorClass::not_found},
      {GP_ERROR_MODEL_NOT_FOUND, ErrorClass::not_found},
      {GP_ERROR_FILE_NOT_FOUND, ErrorClass::not_found},
      {GP_ERROR_CORRUPTED_DATA, ErrorClass::coms_fail},
      {GP_ERROR_NO_SPACE, ErrorClass::needs_operator},
      {GP_ERROR_CAMERA_ERROR, ErrorClass::device_error},
      {GP_ERROR_NO_MEMORY, ErrorClass::internal},
      {GP_ERROR, ErrorClass::hardware_fail},
  };
  for (const auto& [code, cls] : table) {
    const auto e = cam::gphoto2_error(code, "test op");
    EXPECT_EQ(e.cls(), cls) << code;
    EXPECT_EQ(e.info().device_code, "gphoto2:" + std::to_string(code));
    EXPECT_FALSE(e.info().transport_code.empty()) << code;
    EXPECT_FALSE(e.hint().empty()) << code;
    EXPECT_NE(std::string(e.what()).find("test op"), std::string::npos);
  }
  EXPECT_TRUE(cam::gphoto2_error(GP_ERROR_TIMEOUT, "x").info().retryable);
  EXPECT_FALSE(cam::gphoto2_error(GP_ERROR_NOT_SUPPORTED, "x").info().retryable);
}

TEST(camera_gphoto2, raw_file_names) {
  EXPECT_TRUE(cam::is_raw_file_name("IMG_0001.CR2"));
  EXPECT_TRUE(cam::is_raw_file_name("img_0001.dng"));
  EXPECT_FALSE(cam::is_raw_file_name("IMG_0001.JPG"));
  EXPECT_FALSE(cam::is_raw_file_name("README"));
}

namespace {

struct CardDir {
  fs::path root;
  std::vector<std::uint8_t> cr2, jpg;
  CardDir() {
    root = fs::temp_directory_path() / ("colorlab-card-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(root / "DCIM" / "100CANON");
    std::mt19937 rng(7);
    cr2.resize(4096);
    jpg.resize(1500);
    for (auto& b : cr2) b = static_cast<std::uint8_t>(rng());
    for (auto& b : jpg) b = static_cast<std::uint8_t>(rng());
    write("DCIM/100CANON/IMG_0001.CR2", cr2);
    write("DCIM/100CANON/IMG_0001.JPG", jpg);
  }
  ~CardDir() { fs::remove_all(root); }
  void write(const std::string& rel, const std::vector<std::uint8_t>& bytes) const {
    std::ofstream(root / rel, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  cam::Gphoto2Options options() const {
    cam::Gphoto2Options o;
    o.model = "Directory Browse";
    o.port = "disk:" + root.string();
    o.delete_on_card = false;
    return o;
  }
};

}  // namespace

TEST(camera_gphoto2, directory_browse_lists_and_downloads_card_files) {
  CardDir card;
  cam::Gphoto2Camera camera(card.options());
  camera.connect().get();
  EXPECT_EQ(camera.state(), cam::CameraState::ready);
  const auto files = camera.list_files("/").get();
  const cam::CardFile cr2{"/DCIM/100CANON", "IMG_0001.CR2"};
  const cam::CardFile jpg{"/DCIM/100CANON", "IMG_0001.JPG"};
  EXPECT_NE(std::find(files.begin(), files.end(), cr2), files.end());
  EXPECT_NE(std::find(files.begin(), files.end(), jpg), files.end());
  EXPECT_EQ(camera.download(cr2).get(), card.cr2);
  EXPECT_EQ(camera.download(jpg).get(), card.jpg);

  try {
    camera.download({"/DCIM/100CANON", "IMG_9999.CR2"}).get();
    FAIL();
  } catch (const colorlab::Error& e) {
    EXPECT_TRUE(e.cls() == ErrorClass::not_found || e.cls() == ErrorClass::bad_parameter ||
                e.cls() == ErrorClass::internal)
        << to_string(e.cls()) << " " << e.what();
  }

  camera.remove(jpg).get();
  EXPECT_FALSE(fs::exists(card.root / "DCIM/100CANON/IMG_0001.JPG"));
}

TEST(camera_gphoto2, camera_without_capture_reports_unsupported_and_no_frames) {
  CardDir card;
  cam::Gphoto2Camera camera(card.options());
  camera.connect().get();
  EXPECT_TRUE(camera.limits().iso.empty());  // Directory Browse has no configuration
  std::size_t frames = 0;
  auto report = camera.capture(3, [&](const cam::RawImage&) { ++frames; }).get();
  EXPECT_FALSE(report.complete());
  EXPECT_EQ(report.delivered, 0U);
  EXPECT_EQ(frames, 0U);
  ASSERT_TRUE(report.error.has_value());
  EXPECT_EQ(report.error->cls(), ErrorClass::unsupported);
  EXPECT_EQ(report.error->info().device_code, "gphoto2:-6");

  cam::CameraSettings iso;
  iso.iso = 200;
  try {
    camera.configure(iso).get();
    FAIL();
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::unsupported);
  }
}

TEST(camera_gphoto2, missing_port_is_a_typed_error) {
  cam::Gphoto2Options o;
  o.model = "Canon EOS 20D (normal mode)";
  o.port = "usb:999,999";
  cam::Gphoto2Camera camera(o);
  try {
    camera.connect().get();
    FAIL();
  } catch (const colorlab::Error& e) {
    EXPECT_NE(e.cls(), ErrorClass::internal) << e.what();
    EXPECT_FALSE(e.hint().empty());
  }
  EXPECT_EQ(camera.state(), cam::CameraState::disconnected);
}

TEST(camera_gphoto2, dng_downloaded_from_card_decodes_exactly) {
  CardDir card;
  auto model = cam::test::small_model();
  const auto frame = model->render({}, 9);
  colorlab::sim::camera::write_dng(card.root / "DCIM/100CANON/IMG_0009.DNG", frame, {});
  cam::Gphoto2Camera camera(card.options());
  camera.connect().get();
  const auto bytes = camera.download({"/DCIM/100CANON", "IMG_0009.DNG"}).get();
  cam::RawDecoder decoder;
  const auto img = decoder.decode_buffer(bytes, "IMG_0009.DNG");
  ASSERT_EQ(img.width, static_cast<std::size_t>(frame.width));
  EXPECT_TRUE(std::equal(frame.pixels.begin(), frame.pixels.end(), img.contiguous().begin()));
}

TEST(camera_gphoto2, a_call_overrunning_its_deadline_is_a_typed_failure_not_a_hang) {
  CardDir card;
  auto o = card.options();
  o.call_timeout = std::chrono::milliseconds(1);  // init takes longer than this
  cam::Gphoto2Camera impatient(o);
  try {
    impatient.connect().get();
    FAIL() << "connect cannot finish in 1 ms";
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::hardware_fail) << e.what();
    EXPECT_NE(e.hint().find("power-cycle"), std::string::npos);
  }
  EXPECT_EQ(impatient.state(), cam::CameraState::disconnected);

  // Once the late call has returned, the library is usable again.
  cam::Gphoto2Camera patient(card.options());
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  for (;;) {
    try {
      patient.connect().get();
      break;
    } catch (const colorlab::Error& e) {
      ASSERT_EQ(e.cls(), ErrorClass::hardware_fail) << e.what();  // "still stuck", fast
      ASSERT_LT(std::chrono::steady_clock::now(), deadline);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  EXPECT_EQ(patient.state(), cam::CameraState::ready);
  EXPECT_FALSE(patient.list_files("/").get().empty());
}
