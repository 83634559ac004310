#include "colorlab/analysis/rgb_spaces.hpp"

#include <lcms2.h>

#include <memory>

#include "colorlab/core/error.hpp"

namespace colorlab::analysis {

namespace {

struct ProfileCloser {
  void operator()(void* p) const { cmsCloseProfile(p); }
};
struct TransformDeleter {
  void operator()(void* t) const { cmsDeleteTransform(t); }
};
using Profile = std::unique_ptr<void, ProfileCloser>;
using Transform = std::unique_ptr<void, TransformDeleter>;

Profile make_profile(RgbSpace space) {
  if (space == RgbSpace::srgb) return Profile(cmsCreate_sRGBProfile());
  // Adobe RGB (1998): D65 white, its primaries, pure gamma 563/256.
  cmsCIExyY white{0.3127, 0.3290, 1.0};
  cmsCIExyYTRIPLE primaries{{0.64, 0.33, 1.0}, {0.21, 0.71, 1.0}, {0.15, 0.06, 1.0}};
  cmsToneCurve* g = cmsBuildGamma(nullptr, 563.0 / 256.0);
  cmsToneCurve* curves[3] = {g, g, g};
  Profile p(cmsCreateRGBProfile(&white, &primaries, curves));
  cmsFreeToneCurve(g);
  return p;
}

Transform make_transform(Profile& in, cmsUInt32Number in_fmt, Profile& out, cmsUInt32Number out_fmt) {
  // Absolute precision: no 16-bit optimisation of the pipeline, so results are the profile's exact maths.
  Transform t(cmsCreateTransform(in.get(), in_fmt, out.get(), out_fmt, INTENT_RELATIVE_COLORIMETRIC,
                                 cmsFLAGS_NOOPTIMIZE | cmsFLAGS_NOCACHE));
  if (!t) throw Error(ErrorClass::internal, "lcms2 could not build the RGB transform");
  return t;
}

void check_profile(const Profile& p) {
  if (!p) throw Error(ErrorClass::internal, "lcms2 could not create the RGB profile");
}

}  // namespace

std::vector<Xyz> rgb_to_xyz_d50(RgbSpace space, const std::vector<Rgb>& rgb) {
  Profile in = make_profile(space), out(cmsCreateXYZProfile());
  check_profile(in);
  auto t = make_transform(in, TYPE_RGB_DBL, out, TYPE_XYZ_DBL);
  std::vector<Xyz> res(rgb.size());
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    cmsCIEXYZ x;
    cmsDoTransform(t.get(), rgb[i].data(), &x, 1);
    res[i] = {x.X * 100, x.Y * 100, x.Z * 100};
  }
  return res;
}

std::vector<Rgb> xyz_d50_to_rgb(RgbSpace space, const std::vector<Xyz>& xyz) {
  Profile in(cmsCreateXYZProfile()), out = make_profile(space);
  check_profile(out);
  auto t = make_transform(in, TYPE_XYZ_DBL, out, TYPE_RGB_DBL);
  std::vector<Rgb> res(xyz.size());
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    cmsCIEXYZ x{xyz[i].X / 100, xyz[i].Y / 100, xyz[i].Z / 100};
    cmsDoTransform(t.get(), &x, res[i].data(), 1);
  }
  return res;
}

std::vector<Lab> rgb_to_lab_d50(RgbSpace space, const std::vector<Rgb>& rgb) {
  Profile in = make_profile(space), out(cmsCreateLab4Profile(nullptr));
  check_profile(in);
  auto t = make_transform(in, TYPE_RGB_DBL, out, TYPE_Lab_DBL);
  std::vector<Lab> res(rgb.size());
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    cmsCIELab l;
    cmsDoTransform(t.get(), rgb[i].data(), &l, 1);
    res[i] = {l.L, l.a, l.b};
  }
  return res;
}

}  // namespace colorlab::analysis
