#include "colorlab/sim/dslr/dslr_body.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "colorlab/core/error.hpp"
#include "colorlab/sim/camera/dng.hpp"
#include "colorlab/sim/camera/eos20d.hpp"
#include "colorlab/sim/camera/processed.hpp"

namespace colorlab::sim::dslr {

using nlohmann::json;

namespace {

using camera::eos20d::kApertures;
using camera::eos20d::kIsos;
using camera::eos20d::kShutterLabels;
constexpr const char* kFormats[] = {"raw", "raw+jpeg", "raw+jpeg+tiff"};

double label_seconds(const std::string& label) {
  if (label.rfind("1/", 0) == 0) return 1.0 / std::stod(label.substr(2));
  return std::stod(label);
}

// The label whose time is closest to `seconds` (the model's default 1/30 s is exactly a label).
std::string shutter_label(double seconds) {
  std::string best = kShutterLabels[0];
  for (const char* l : kShutterLabels) {
    if (std::abs(std::log(label_seconds(l) / seconds)) < std::abs(std::log(label_seconds(best) / seconds))) best = l;
  }
  return best;
}

}  // namespace

DslrBody::DslrBody(std::shared_ptr<const camera::CameraModel> model, DslrBodyConfig config)
    : model_(std::move(model)), config_(std::move(config)) {
  if (!model_) throw Error(ErrorClass::bad_parameter, "the simulated DSLR needs a camera model");
  std::error_code ec;
  std::filesystem::create_directories(config_.capture_dir, ec);
  if (ec) {
    throw Error(ErrorClass::io_error,
                "simulated DSLR: cannot create capture directory " + config_.capture_dir.string() +
                    ": " + ec.message(),
                "check [dslr] capture_dir and its permissions");
  }
  // XYZ -> camera under D65 does not depend on which lamps are lit: computed once.
  color_matrix_ = model_->xyz_to_camera_d65();
  exposure_.shutter_s = label_seconds(shutter_label(exposure_.shutter_s));
}

json DslrBody::settings() const {
  std::lock_guard lock(mutex_);
  return {{"iso", exposure_.iso},
          {"shutter", shutter_label(exposure_.shutter_s)},
          {"aperture", exposure_.f_number},
          {"image_format", image_format_}};
}

json DslrBody::identify() const {
  json shutters = json::array();
  for (const char* l : kShutterLabels) shutters.push_back(l);
  return {{"make", "colorlab"},
          {"model", "Simulated EOS 20D"},
          {"serial", config_.serial},
          {"firmware", "colorlab-sim"},
          {"limits",
           {{"iso", std::vector<int>(std::begin(kIsos), std::end(kIsos))},
            {"shutter", shutters},
            {"aperture", std::vector<double>(std::begin(kApertures), std::end(kApertures))},
            {"image_formats", std::vector<std::string>(std::begin(kFormats), std::end(kFormats))}}},
          {"settings", settings()}};
}

json DslrBody::configure(const json& r) {
  camera::CameraSettings next;
  std::string format;
  {
    std::lock_guard lock(mutex_);
    next = exposure_;
    format = image_format_;
  }
  auto refuse = [](const std::string& what) -> Refusal { return Refusal{"bad_value", what}; };
  try {
    if (r.contains("iso")) {
      const int iso = r["iso"].get<int>();
      if (std::find(std::begin(kIsos), std::end(kIsos), iso) == std::end(kIsos)) throw refuse("iso " + std::to_string(iso) + " is not offered");
      next.iso = iso;
    }
    if (r.contains("shutter")) {
      const std::string label = r["shutter"].get<std::string>();
      if (std::find_if(std::begin(kShutterLabels), std::end(kShutterLabels), [&](const char* l) { return label == l; }) ==
          std::end(kShutterLabels)) {
        throw refuse("shutter '" + label + "' is not one of the camera's labels");
      }
      next.shutter_s = label_seconds(label);
    }
    if (r.contains("aperture")) {
      const double f = r["aperture"].get<double>();
      const auto* hit = std::find_if(std::begin(kApertures), std::end(kApertures), [&](double a) { return std::abs(a - f) < 1e-6; });
      if (hit == std::end(kApertures)) throw refuse("aperture f/" + r["aperture"].dump() + " is not offered");
      next.f_number = *hit;
    }
    if (r.contains("image_format")) {
      format = r["image_format"].get<std::string>();
      if (std::find_if(std::begin(kFormats), std::end(kFormats), [&](const char* f) { return format == f; }) == std::end(kFormats)) {
        throw refuse("image format '" + format + "' is not offered");
      }
    }
  } catch (const json::exception& e) {
    throw Refusal{"bad_request", std::string("configure: a setting has the wrong type: ") + e.what()};
  }
  {
    std::lock_guard lock(mutex_);
    exposure_ = next;
    image_format_ = format;
  }
  return {{"settings", settings()}};
}

json DslrBody::remove(const json& r) {
  if (!r.contains("names") || !r["names"].is_array()) throw Refusal{"bad_request", "delete needs \"names\": [file names]"};
  int deleted = 0;
  for (const auto& n : r["names"]) {
    if (!n.is_string()) throw Refusal{"bad_request", "file names are strings"};
    const std::filesystem::path name = n.get<std::string>();
    // Only plain names inside the capture directory: the camera has no other files to delete.
    if (name.has_parent_path() || name.filename() != name) throw Refusal{"bad_request", "'" + name.string() + "' is not a file name"};
    std::error_code ec;
    if (!std::filesystem::remove(config_.capture_dir / name, ec)) throw Refusal{"not_found", "no file " + name.string() + " on the card"};
    ++deleted;
  }
  return {{"deleted", deleted}};
}

ShotPlan DslrBody::plan_shot() {
  std::lock_guard lock(mutex_);
  return ShotPlan{shots_++, exposure_, image_format_};
}

double DslrBody::shot_seconds(const ShotPlan& plan) const {
  const int sidecars = plan.image_format == "raw" ? 0 : plan.image_format == "raw+jpeg" ? 1
                                                                                        : 3;
  return config_.release_s + plan.exposure.shutter_s + config_.transfer_s + sidecars * config_.sidecar_transfer_s;
}

ShotResult DslrBody::take(const ShotPlan& plan) const {
  ShotResult result;
  result.plan = plan;
  const camera::RawFrame raw = model_->render(plan.exposure, plan.shot);
  result.truth = model_->ground_truth(plan.exposure);

  char base[16];
  std::snprintf(base, sizeof base, "IMG_%04llu", static_cast<unsigned long long>(plan.shot % 9999 + 1));
  auto add = [&](const std::string& name, const std::string& type) {
    const auto path = config_.capture_dir / name;
    result.files.push_back(ShotFile{name, path, type, static_cast<std::uint64_t>(std::filesystem::file_size(path))});
  };
  camera::DngMetadata meta;
  meta.color_matrix1 = color_matrix_;
  meta.as_shot_neutral = model_->as_shot_neutral();
  camera::write_dng(config_.capture_dir / (std::string(base) + ".DNG"), raw, meta);
  add(std::string(base) + ".DNG", "raw");

  if (plan.image_format != "raw") {
    const camera::RgbImage developed = camera::develop(raw, *model_);
    try {
      camera::write_jpeg(config_.capture_dir / (std::string(base) + ".JPG"), developed);
      add(std::string(base) + ".JPG", "jpeg");
    } catch (const Error& e) {
      if (e.cls() != ErrorClass::unsupported) throw;  // built without libjpeg: no JPEG to offer
    }
    if (plan.image_format == "raw+jpeg+tiff") {
      camera::write_tiff(config_.capture_dir / (std::string(base) + ".TIF"), developed, 8);
      add(std::string(base) + ".TIF", "tiff8");
      camera::write_tiff(config_.capture_dir / (std::string(base) + "_16.TIF"), developed, 16);
      add(std::string(base) + "_16.TIF", "tiff16");
    }
  }
  return result;
}

}  // namespace colorlab::sim::dslr
