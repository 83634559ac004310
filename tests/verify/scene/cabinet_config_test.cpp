// The [cabinet] table of the lab configuration: defaults, overrides, and a typed error naming file and line for
// each kind of bad value.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "colorlab/core/error.hpp"
#include "colorlab/verify/cabinet.hpp"
#include "colorlab/verify/cabinet_toml.hpp"

namespace colorlab::verify {
namespace {

std::filesystem::path write(const std::string& name, const std::string& text) {
  auto p = std::filesystem::temp_directory_path() / ("colorlab-cabinet-" + std::to_string(::getpid()) + "-" + name + ".toml");
  std::ofstream(p) << text;
  return p;
}

std::string refusal(const std::string& text) {
  const auto p = write("bad", text);
  try {
    cabinet_from_file(p);
  } catch (const Error& e) {
    std::filesystem::remove(p);
    EXPECT_EQ(e.info().cls, ErrorClass::bad_parameter);
    return e.what();
  }
  std::filesystem::remove(p);
  ADD_FAILURE() << "accepted: " << text;
  return {};
}

TEST(CabinetConfig, TheDefaultCabinetIsValidAndHasTheDissertationsWidth) {
  const auto c = default_cabinet();
  EXPECT_NO_THROW(validate(c));
  EXPECT_EQ(c.width_mm, 1200.0);  // appendix C.1: "of 120 cm width"
  for (const char* lamp : {"D65", "TL84", "CWF", "A", "UV"}) {
    ASSERT_NE(emitter_of(c, lamp), nullptr) << lamp;
    EXPECT_GT(emitter_of(c, lamp)->luminance_cd_m2, 0.0) << lamp;
  }
  EXPECT_EQ(emitter_of(c, "d65"), emitter_of(c, "D65"));
}

TEST(CabinetConfig, ATableOverridesTheDefaultsAndItsEmittersReplaceThem) {
  const auto p = write("ok", "[cabinet]\nheight_mm = 550\nchart_center_mm = [500, 150]\n"
                             "[[cabinet.emitter]]\nlamp = \"D65\"\ncenter_mm = [600, 120]\nsize_mm = [900, 90]\n"
                             "luminance_cd_m2 = 15000\n");
  const auto c = cabinet_from_file(p);
  std::filesystem::remove(p);
  EXPECT_EQ(c.height_mm, 550.0);
  EXPECT_EQ(c.chart_center_x_mm, 500.0);
  ASSERT_EQ(c.emitters.size(), 1u);
  EXPECT_EQ(c.emitters[0].length_mm, 900.0);
  EXPECT_EQ(c.emitters[0].luminance_cd_m2, 15000.0);
  const auto none = write("none", "seed = 3\n");
  EXPECT_EQ(cabinet_from_file(none).emitters.size(), default_cabinet().emitters.size());
  std::filesystem::remove(none);
}

TEST(CabinetConfig, BadValuesAreRefusedNamingTheFileTheLineAndWhatIsWrong) {
  using ::testing::HasSubstr;
  EXPECT_THAT(refusal("[cabinet]\nwidth = 3\n"), HasSubstr(":2: unknown key cabinet.width"));
  EXPECT_THAT(refusal("[cabinet]\nheight_mm = -1\n"), HasSubstr("height_mm must be in (0, 10000]"));
  EXPECT_THAT(refusal("[cabinet]\nfloor_reflectance = 1.5\n"), HasSubstr("floor_reflectance must be within 0..1"));
  EXPECT_THAT(refusal("[cabinet]\ndepth_mm = \"deep\"\n"), HasSubstr(":2: cabinet.depth_mm must be a number"));
  EXPECT_THAT(refusal("[cabinet]\nchart_center_mm = [600]\n"), HasSubstr("chart_center_mm must be [x, y]"));
  EXPECT_THAT(refusal("[cabinet]\nchart_center_mm = [600, 900]\n"), HasSubstr("is off the floor"));
  const std::string e = "[[cabinet.emitter]]\nlamp = \"D65\"\ncenter_mm = [600, 100]\nsize_mm = [1000, 100]\n";
  EXPECT_THAT(refusal(e + e), HasSubstr("emitter \"D65\" is given twice"));
  EXPECT_THAT(refusal("[[cabinet.emitter]]\nlamp = \"F7\"\ncenter_mm = [600, 100]\nsize_mm = [100, 100]\n"),
              HasSubstr("lamp must be one of D65, TL84, CWF, A, UV"));
  EXPECT_THAT(refusal("[[cabinet.emitter]]\nlamp = \"A\"\ncenter_mm = [100, 100]\nsize_mm = [400, 100]\n"),
              HasSubstr("reaches outside the 1200 × 600 mm ceiling"));
  EXPECT_THAT(refusal("[[cabinet.emitter]]\nlamp = \"A\"\ncenter_mm = [600, 100]\n"),
              HasSubstr(":1: cabinet.emitter needs lamp, center_mm and size_mm"));
  EXPECT_THAT(refusal("[[cabinet.emitter]]\nlamp = \"A\"\ncenter_mm = [600, 100]\nsize_mm = [10, 10]\nlumen = 3\n"),
              HasSubstr(":5: unknown key cabinet.emitter.lumen"));
  EXPECT_THAT(refusal("cabinet = 3\n"), HasSubstr(":1: [cabinet] must be a table"));
}

}  // namespace
}  // namespace colorlab::verify
