// Typed settings against a camera's limits, and the shutter labels DSLR firmwares use.
#include <gtest/gtest.h>

#include <cmath>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/camera/camera_settings.hpp"

namespace cam = colorlab::drivers::camera;
using colorlab::ErrorClass;

namespace {

cam::CameraLimits dslr() {
  cam::CameraLimits l;
  l.iso = {100, 200, 400, 800, 1600};
  l.shutter_s = {1.0 / 125, 1.0 / 60, 1.0 / 30, 0.5, 1, 2.5};
  l.aperture_f = {4, 5.6, 8, 11};
  l.image_formats = {cam::ImageFormat::raw, cam::ImageFormat::raw_and_jpeg};
  return l;
}

ErrorClass class_of(const cam::CameraSettings& s, const cam::CameraLimits& l) {
  try {
    cam::validate(s, l, "test camera");
  } catch (const colorlab::Error& e) {
    EXPECT_FALSE(e.hint().empty());
    EXPECT_NE(std::string(e.what()).find("test camera"), std::string::npos);
    return e.cls();
  }
  return ErrorClass::internal;  // "no error" marker for these tests
}

}  // namespace

TEST(camera_settings, accepts_listed_choices_within_one_percent) {
  cam::CameraSettings s;
  s.iso = 400;
  s.shutter_s = 0.0167;  // 1/60 written with 3 digits
  s.aperture_f = 5.6;
  s.image_format = cam::ImageFormat::raw;
  EXPECT_NO_THROW(cam::validate(s, dslr(), "test camera"));
}

TEST(camera_settings, rejects_values_the_camera_does_not_offer) {
  cam::CameraSettings s;
  s.iso = 250;
  EXPECT_EQ(class_of(s, dslr()), ErrorClass::bad_parameter);
  s = {};
  s.shutter_s = 1.0 / 50;
  EXPECT_EQ(class_of(s, dslr()), ErrorClass::bad_parameter);
  s = {};
  s.image_format = cam::ImageFormat::jpeg;
  EXPECT_EQ(class_of(s, dslr()), ErrorClass::bad_parameter);
}

TEST(camera_settings, genicam_settings_on_a_dslr_are_unsupported_and_vice_versa) {
  cam::CameraSettings s;
  s.exposure_us = 1000;
  EXPECT_EQ(class_of(s, dslr()), ErrorClass::unsupported);
  cam::CameraLimits genicam;
  genicam.exposure_us = cam::Range{10, 1e7};
  genicam.gain = cam::Range{0, 10};
  genicam.pixel_formats = {cam::PixelFormat::bayer_rg12};
  s = {};
  s.iso = 100;
  EXPECT_EQ(class_of(s, genicam), ErrorClass::unsupported);
  s = {};
  s.exposure_us = 5;
  EXPECT_EQ(class_of(s, genicam), ErrorClass::bad_parameter);
  s.exposure_us = std::nan("");
  EXPECT_EQ(class_of(s, genicam), ErrorClass::bad_parameter);
  s = {};
  s.pixel_format = cam::PixelFormat::mono16;
  EXPECT_EQ(class_of(s, genicam), ErrorClass::bad_parameter);
}

TEST(camera_settings, shutter_labels_round_trip) {
  EXPECT_NEAR(*cam::parse_shutter_label("1/60"), 1.0 / 60, 1e-12);
  EXPECT_NEAR(*cam::parse_shutter_label("1/4000"), 1.0 / 4000, 1e-12);
  EXPECT_NEAR(*cam::parse_shutter_label("2.5"), 2.5, 1e-12);
  EXPECT_NEAR(*cam::parse_shutter_label("30\""), 30, 1e-12);
  EXPECT_NEAR(*cam::parse_shutter_label("0.5s"), 0.5, 1e-12);
  EXPECT_FALSE(cam::parse_shutter_label("Bulb"));
  EXPECT_FALSE(cam::parse_shutter_label(""));
  EXPECT_EQ(cam::format_shutter_label(1.0 / 60), "1/60");
  EXPECT_EQ(cam::format_shutter_label(2.5), "2.5");
}

TEST(camera_settings, merge_keeps_unset_fields) {
  cam::CameraSettings a;
  a.iso = 100;
  a.aperture_f = 8;
  cam::CameraSettings b;
  b.iso = 400;
  a.merge(b);
  EXPECT_EQ(a.iso, 400);
  EXPECT_EQ(a.aperture_f, 8);
}

TEST(camera_settings, pixel_format_names_are_genicam_names) {
  EXPECT_EQ(cam::pixel_format_from_string("BayerRG12"), cam::PixelFormat::bayer_rg12);
  EXPECT_EQ(cam::to_string(cam::PixelFormat::mono16), "Mono16");
  EXPECT_THROW(cam::pixel_format_from_string("BayerRG12p"), colorlab::Error);
}
