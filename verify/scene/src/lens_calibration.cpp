#include "colorlab/verify/lens_calibration.hpp"
#include "colorlab/verify/lens_toml.hpp"

#include <cmath>
#include <iomanip>
#include <set>
#include <sstream>

#include <opencv2/calib3d.hpp>

#include "colorlab/analysis/chart_layout.hpp"
#include "colorlab/core/error.hpp"

namespace colorlab::verify {

namespace {

constexpr const char* kHint = "see docs/verify.md, \"The lens calibration\"";
constexpr std::array<const char*, 6> kParams{"fx", "fy", "cx", "cy", "k1", "k2"};

constexpr std::array<double CameraIntrinsics::*, 6> kMembers{&CameraIntrinsics::fx, &CameraIntrinsics::fy, &CameraIntrinsics::cx,
                                                             &CameraIntrinsics::cy, &CameraIntrinsics::k1, &CameraIntrinsics::k2};
double& param(CameraIntrinsics& k, std::size_t i) { return k.*kMembers[i]; }
double param(const CameraIntrinsics& k, std::size_t i) { return k.*kMembers[i]; }

std::string quoted(const std::string& v) {
  std::string q = "\"";
  for (char c : v) {
    if (c == '"' || c == '\\') q += '\\';
    if (c == '\n') q += "\\n";
    else q += c;
  }
  return q + "\"";
}

// One rule set for both TOML and JSON: what makes a calibration usable. Returns what is wrong, "" when nothing.
std::string problem(const LensCalibration& l) {
  if (l.camera.empty() || l.lens.empty()) return "needs camera and lens (the body and the lens it calibrates)";
  if (l.width_px <= 0 || l.height_px <= 0) return "width_px and height_px must be > 0 (the photographs' size)";
  if (!(l.intrinsics.fx > 0 && l.intrinsics.fy > 0)) return "fx and fy must be > 0 (pixels)";
  if (!(l.intrinsics.cx >= 0 && l.intrinsics.cx <= l.width_px - 1 && l.intrinsics.cy >= 0 && l.intrinsics.cy <= l.height_px - 1))
    return "the principal point (cx, cy) must lie inside the width_px × height_px frame";
  for (std::size_t i = 0; i < kParams.size(); ++i)
    if (!std::isfinite(param(l.intrinsics, i)) || !(param(l.sigma, i) >= 0) || !std::isfinite(param(l.sigma, i)))
      return std::string(kParams[i]) + " and its sigma must be finite, sigma ≥ 0";
  if (l.focal_length_mm && !(*l.focal_length_mm > 0)) return "focal_length_mm must be > 0";
  return "";
}

}  // namespace

std::string LensCalibration::name() const {
  std::ostringstream s;
  s << camera << " / " << lens;
  if (focal_length_mm) s << " @ " << *focal_length_mm << " mm";
  if (!focus.empty()) s << ", focus " << focus;
  return s.str();
}

LensCalibration calibrate_lens(const std::vector<CalibrationView>& views, int width_px, int height_px) {
  if (views.size() < 3)
    throw Error(ErrorClass::bad_parameter,
                "lens calibration needs photographs of the chart at 3 or more poses, got " + std::to_string(views.size()),
                "photograph the chart tilted different ways and placed across the frame, corners included");
  if (width_px <= 0 || height_px <= 0) throw Error(ErrorClass::bad_parameter, "lens calibration: the photographs' size must be > 0");
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> image;
  int points = 0;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const auto& view = views[v];
    if (view.image_px.size() != view.chart_mm.size() || view.image_px.size() < 20)
      throw Error(ErrorClass::bad_parameter, "lens calibration: photograph " + std::to_string(v + 1) + " has " +
                                                 std::to_string(view.image_px.size()) + " image and " + std::to_string(view.chart_mm.size()) +
                                                 " chart points (needs the same number, ≥ 20)");
    object.emplace_back(), image.emplace_back();
    for (std::size_t i = 0; i < view.image_px.size(); ++i) {
      object.back().emplace_back(static_cast<float>(view.chart_mm[i][0]), static_cast<float>(view.chart_mm[i][1]), 0.f);
      image.back().emplace_back(static_cast<float>(view.image_px[i][0]), static_cast<float>(view.image_px[i][1]));
    }
    points += static_cast<int>(view.image_px.size());
  }
  cv::Mat K, D, sd_intrinsics, sd_extrinsics, per_view;
  std::vector<cv::Mat> rvecs, tvecs;
  // scene.json's model is radial k1, k2: tangential terms and k3 are held at 0 rather than fitted and dropped.
  const double rms = cv::calibrateCamera(object, image, cv::Size(width_px, height_px), K, D, rvecs, tvecs, sd_intrinsics,
                                         sd_extrinsics, per_view, cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K3);
  LensCalibration l;
  l.width_px = width_px, l.height_px = height_px;
  l.intrinsics = {K.at<double>(0, 0), K.at<double>(1, 1), K.at<double>(0, 2), K.at<double>(1, 2), D.at<double>(0), D.at<double>(1)};
  // OpenCV's order: fx, fy, cx, cy, k1, k2, p1, p2, k3, …
  l.sigma = {sd_intrinsics.at<double>(0), sd_intrinsics.at<double>(1), sd_intrinsics.at<double>(2),
             sd_intrinsics.at<double>(3), sd_intrinsics.at<double>(4), sd_intrinsics.at<double>(5)};
  l.rms_px = rms;
  l.photographs = static_cast<int>(views.size());
  l.points = points;
  l.camera = "?", l.lens = "?";
  if (const std::string p = problem(l); !p.empty())
    throw Error(ErrorClass::bad_data, "lens calibration gave no usable lens: " + p,
                "use more photographs, with the chart tilted and reaching the frame's corners");
  return l;
}

LensCalibration calibrate_lens_from_chart(const std::string& chart, const std::vector<ObservedCentres>& photographs, int width_px,
                                          int height_px, const LensIdentity& who, const std::string& by) {
  const analysis::ChartLayout& layout = analysis::chart_layout(analysis::chart_type_from_string(chart));
  std::vector<CalibrationView> views;
  for (std::size_t v = 0; v < photographs.size(); ++v) {
    const auto& observed = photographs[v];
    if (observed.size() != static_cast<std::size_t>(layout.size()))
      throw Error(ErrorClass::bad_parameter, "lens calibration: photograph " + std::to_string(v + 1) + " has " +
                                                 std::to_string(observed.size()) + " patch centres, the " + layout.name + " has " +
                                                 std::to_string(layout.size()) + " patches");
    CalibrationView view;
    for (int k = 0; k < layout.size(); ++k) {
      const auto& at = observed[static_cast<std::size_t>(k)];
      if (!at) continue;
      view.image_px.push_back(*at);
      view.chart_mm.push_back({layout.centre_x(k), layout.centre_y(k)});
    }
    views.push_back(std::move(view));
  }
  LensCalibration l = calibrate_lens(views, width_px, height_px);
  l.camera = who.camera, l.lens = who.lens, l.focus = who.focus, l.date = who.date;
  l.focal_length_mm = who.focal_length_mm;
  l.source = by + ": OpenCV calibrateCamera over " + std::to_string(views.size()) + " photographs of the " + layout.name +
             " (detected patch centres)";
  return l;
}

std::vector<LensCalibration> lenses_from_toml(const toml::array& tables, const std::string& file) {
  std::vector<LensCalibration> out;
  std::set<std::string> names;
  for (const auto& node : tables) {
    const auto where = [&](const toml::node& n) { return file + ":" + std::to_string(n.source().begin.line) + ": lens: "; };
    const auto* t = node.as_table();
    if (!t) throw Error(ErrorClass::bad_parameter, where(node) + "[[lens]] entries must be tables", kHint);
    LensCalibration l;
    bool have[6] = {};
    const auto num = [&](const toml::node& v, const std::string& key) {
      const auto d = v.value<double>();
      if (!d) throw Error(ErrorClass::bad_parameter, where(v) + key + " must be a number", kHint);
      return *d;
    };
    const auto str = [&](const toml::node& v, const std::string& key) {
      const auto s = v.value<std::string>();
      if (!s) throw Error(ErrorClass::bad_parameter, where(v) + key + " must be a string", kHint);
      return *s;
    };
    for (const auto& [k, v] : *t) {
      const std::string key(k.str());
      std::size_t i = 0;
      while (i < kParams.size() && key != kParams[i]) ++i;
      if (i < kParams.size()) param(l.intrinsics, i) = num(v, key), have[i] = true;
      else if (key == "camera") l.camera = str(v, key);
      else if (key == "lens") l.lens = str(v, key);
      else if (key == "focus") l.focus = str(v, key);
      else if (key == "source") l.source = str(v, key);
      else if (key == "date") l.date = str(v, key);
      else if (key == "focal_length_mm") l.focal_length_mm = num(v, key);
      else if (key == "width_px") l.width_px = static_cast<int>(num(v, key));
      else if (key == "height_px") l.height_px = static_cast<int>(num(v, key));
      else if (key == "rms_px") l.rms_px = num(v, key);
      else if (key == "photographs") l.photographs = static_cast<int>(num(v, key));
      else if (key == "points") l.points = static_cast<int>(num(v, key));
      else if (key == "sigma") {
        const auto* s = v.as_table();
        if (!s) throw Error(ErrorClass::bad_parameter, where(v) + "sigma must be a table {fx, fy, cx, cy, k1, k2}", kHint);
        for (const auto& [sk, sv] : *s) {
          std::size_t j = 0;
          while (j < kParams.size() && sk.str() != kParams[j]) ++j;
          if (j == kParams.size())
            throw Error(ErrorClass::bad_parameter, where(sv) + "unknown key sigma." + std::string(sk.str()) + " (fx, fy, cx, cy, k1, k2)", kHint);
          param(l.sigma, j) = num(sv, "sigma." + std::string(sk.str()));
        }
      } else {
        throw Error(ErrorClass::bad_parameter,
                    where(v) + "unknown key " + key +
                        " (camera, lens, focal_length_mm, focus, width_px, height_px, fx, fy, cx, cy, k1, k2, sigma, rms_px, "
                        "photographs, points, source, date)",
                    kHint);
      }
    }
    for (std::size_t i = 0; i < 4; ++i)
      if (!have[i]) throw Error(ErrorClass::bad_parameter, where(node) + "missing " + kParams[i], kHint);
    if (const std::string p = problem(l); !p.empty()) throw Error(ErrorClass::bad_parameter, where(node) + p, kHint);
    if (!names.insert(l.name()).second)
      throw Error(ErrorClass::bad_parameter, where(node) + "\"" + l.name() + "\" is calibrated twice", "keep one [[lens]] per camera, lens and setting");
    out.push_back(std::move(l));
  }
  return out;
}

std::vector<LensCalibration> lenses_from_file(const std::string& path) {
  toml::table doc;
  try {
    doc = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw Error(ErrorClass::bad_parameter, path + ":" + std::to_string(e.source().begin.line) + ": " + std::string(e.description()), kHint);
  }
  const auto* node = doc.get("lens");
  if (!node) return {};
  const auto* a = node->as_array();
  if (!a) throw Error(ErrorClass::bad_parameter, path + ":" + std::to_string(node->source().begin.line) + ": lens: must be [[lens]] tables", kHint);
  return lenses_from_toml(*a, path);
}

std::string lens_to_toml(const LensCalibration& l) {
  std::ostringstream s;
  s << std::setprecision(10);
  const auto q = quoted;
  s << "[[lens]]\ncamera = " << q(l.camera) << "\nlens = " << q(l.lens) << "\n";
  if (l.focal_length_mm) s << "focal_length_mm = " << *l.focal_length_mm << "\n";
  if (!l.focus.empty()) s << "focus = " << q(l.focus) << "\n";
  s << "width_px = " << l.width_px << "\nheight_px = " << l.height_px << "\n";
  for (std::size_t i = 0; i < kParams.size(); ++i) s << kParams[i] << " = " << param(l.intrinsics, i) << "\n";
  s << "sigma = { ";
  for (std::size_t i = 0; i < kParams.size(); ++i) s << (i ? ", " : "") << kParams[i] << " = " << param(l.sigma, i);
  s << " }   # one standard uncertainty\nrms_px = " << l.rms_px << "\nphotographs = " << l.photographs << "\npoints = " << l.points
    << "\nsource = " << q(l.source) << "\ndate = " << q(l.date) << "\n";
  return s.str();
}

nlohmann::json lens_to_json(const LensCalibration& l) {
  nlohmann::json j{
      {"name", l.name()},
      {"camera", l.camera},
      {"lens", l.lens},
      {"focus", l.focus},
      {"width_px", l.width_px},
      {"height_px", l.height_px},
      {"rms_px", l.rms_px},
      {"photographs", l.photographs},
      {"points", l.points},
      {"source", l.source},
      {"date", l.date},
  };
  j["focal_length_mm"] = l.focal_length_mm ? nlohmann::json(*l.focal_length_mm) : nlohmann::json(nullptr);
  nlohmann::json sigma;
  for (std::size_t i = 0; i < kParams.size(); ++i) j[kParams[i]] = param(l.intrinsics, i), sigma[kParams[i]] = param(l.sigma, i);
  j["sigma"] = sigma;
  return j;
}

LensCalibration lens_from_json(const nlohmann::json& j, const std::string& where) {
  const auto bad = [&](const std::string& what) {
    return Error(ErrorClass::bad_data, where + ": lens calibration: " + what, kHint);
  };
  if (!j.is_object()) throw bad("not an object");
  LensCalibration l;
  try {
    l.camera = j.at("camera").get<std::string>();
    l.lens = j.at("lens").get<std::string>();
    l.focus = j.value("focus", std::string());
    if (j.contains("focal_length_mm") && !j["focal_length_mm"].is_null()) l.focal_length_mm = j["focal_length_mm"].get<double>();
    l.width_px = j.at("width_px").get<int>();
    l.height_px = j.at("height_px").get<int>();
    for (std::size_t i = 0; i < kParams.size(); ++i) {
      param(l.intrinsics, i) = j.at(kParams[i]).get<double>();
      param(l.sigma, i) = j.at("sigma").at(kParams[i]).get<double>();
    }
    l.rms_px = j.value("rms_px", 0.0);
    l.photographs = j.value("photographs", 0);
    l.points = j.value("points", 0);
    l.source = j.value("source", std::string());
    l.date = j.value("date", std::string());
  } catch (const nlohmann::json::exception& e) {
    throw bad(std::string("malformed (") + e.what() + ")");
  }
  if (const std::string p = problem(l); !p.empty()) throw bad(p);
  return l;
}

std::optional<LensCalibration> choose_lens(const std::vector<LensCalibration>& lenses, const std::string& name, int width_px,
                                           int height_px) {
  std::string known;
  for (const auto& l : lenses) known += (known.empty() ? "" : "; ") + l.name();
  if (!name.empty()) {
    for (const auto& l : lenses)
      if (l.name() == name) return l;
    throw Error(ErrorClass::bad_parameter, "no lens calibration named \"" + name + "\"",
                known.empty() ? "the lab configuration has no [[lens]]" : "the lab's calibrations: " + known);
  }
  std::vector<const LensCalibration*> fit;
  for (const auto& l : lenses)
    if (l.width_px == width_px && l.height_px == height_px) fit.push_back(&l);
  if (fit.empty()) return std::nullopt;
  if (fit.size() > 1)
    throw Error(ErrorClass::bad_parameter,
                std::to_string(fit.size()) + " lens calibrations hold for " + std::to_string(width_px) + " × " +
                    std::to_string(height_px) + " photographs",
                "name one with --lens-calibration NAME (the lab's: " + known + ")");
  return *fit.front();
}

}  // namespace colorlab::verify
