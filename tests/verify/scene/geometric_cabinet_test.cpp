// The simulator's opt-in geometric cabinet: the floor lit by the emitters' form factors, the §6.2 field
// untouched by default, and the lab file's [cabinet] and floor_field read with typed errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "colorlab/core/error.hpp"
#include "colorlab/sim/lab_config.hpp"
#include "colorlab/sim/scene.hpp"

namespace colorlab::sim {
namespace {

std::shared_ptr<SimClock> clock() { return std::make_shared<SimClock>(1.0); }

TEST(GeometricCabinet, TheFloorIsEachEmittersDirectLightAndTheDefaultFieldIsUnmoved) {
  SceneConfig geometric;
  geometric.geometric_cabinet = verify::default_cabinet();
  geometric.lamps_on_at_start = {Lamp::d65, Lamp::cwf};
  const Scene g(geometric, clock());
  const auto cab = verify::default_cabinet();
  for (int r : {0, 3, 7}) {
    for (int c : {0, 9, 19}) {
      const auto [x, y] = Scene::floor_spot_position_mm(r, c);
      double truth = 0;
      for (const char* lamp : {"D65", "CWF"}) {
        const auto* e = verify::emitter_of(cab, lamp);
        truth += 0.30 * e->luminance_cd_m2 * verify::form_factor(*e, cab.height_mm, x, y);
      }
      EXPECT_NEAR(g.floor_luminance(r, c) / truth, 1.0, 1e-12) << r << "," << c;
    }
  }
  // The default scene still has the §6.2 shape (brightest at the middle front, D65 ≈ 320 cd/m²).
  SceneConfig plain;
  plain.lamps_on_at_start = {Lamp::d65};
  const Scene p(plain, clock());
  EXPECT_GT(p.floor_luminance(0, 9), 300.0);
  EXPECT_NE(p.floor_luminance(0, 9), g.lamp_floor_luminance(Lamp::d65, 100, 570, 27));
  // The chart lies where the cabinet says.
  EXPECT_EQ(g.config().chart_center_x_mm, cab.chart_center_x_mm);
}

TEST(GeometricCabinet, RefusesACabinetTheSimulatedFloorCannotBe) {
  auto refused = [](verify::CabinetGeometry cab, const std::string& what) {
    SceneConfig c;
    c.geometric_cabinet = std::move(cab);
    try {
      Scene s(c, clock());
      ADD_FAILURE() << "accepted; wanted " << what;
    } catch (const Error& e) {
      EXPECT_EQ(e.cls(), ErrorClass::bad_parameter);
      EXPECT_THAT(e.what(), ::testing::HasSubstr(what));
    }
  };
  auto cab = verify::default_cabinet();
  cab.floor_reflectance = 0.5;
  refused(cab, "floor_reflectance must be the simulated floor's 0.3");
  cab = verify::default_cabinet();
  cab.depth_mm = 700;  // every panel still fits the ceiling: only the simulator objects
  refused(cab, "the simulated floor is 1200 × 600 mm");
  cab = verify::default_cabinet();
  cab.emitters[1].luminance_cd_m2 = 0;
  refused(cab, "emitter A needs its luminance_cd_m2");
}

TEST(GeometricCabinet, TheLabFileSwitchesItOnAndDescribesTheCabinet) {
  const auto dir = std::filesystem::temp_directory_path() / ("colorlab-geo-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "lab.toml") << "[scene]\nfloor_field = \"geometric\"\n[cabinet]\nheight_mm = 500\n";
  const LabConfig c = load_lab_config(dir / "lab.toml");
  EXPECT_TRUE(c.geometric_floor);
  EXPECT_EQ(c.cabinet.height_mm, 500.0);
  std::ofstream(dir / "plain.toml") << "seed = 2\n";
  EXPECT_FALSE(load_lab_config(dir / "plain.toml").geometric_floor);
  std::ofstream(dir / "bad.toml") << "[scene]\nfloor_field = \"raytraced\"\n";
  try {
    load_lab_config(dir / "bad.toml");
    ADD_FAILURE() << "accepted floor_field = raytraced";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("bad.toml:2: scene.floor_field must be"));
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace colorlab::sim
