// Lamp names, the clock, seeded streams, and the absolute scale of the scene's spectra.
#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/sim/clock.hpp"
#include "colorlab/sim/scene.hpp"

namespace colorlab::sim {
namespace {

SceneConfig quick(std::uint64_t seed = 1) {
  SceneConfig c;
  c.seed = seed;
  c.force_synthetic_chart = true;
  return c;
}

analysis::SpectralSet as_set(const Spectrum& s) {
  analysis::SpectralSet set;
  set.values.resize(1, static_cast<Eigen::Index>(s.values.size()));
  for (std::size_t i = 0; i < s.values.size(); ++i) {
    set.wavelengths.push_back(s.wavelength(i));
    set.values(0, static_cast<Eigen::Index>(i)) = s.values[i];
  }
  set.names = {"s"};
  set.source = "test";
  return set;
}

TEST(SimLamps, NamesRoundTripAndAliasesAreAccepted) {
  for (Lamp l : all_lamps) EXPECT_EQ(lamp_from_string(to_string(l)), l);
  EXPECT_EQ(lamp_from_string("f11"), Lamp::tl84);
  EXPECT_EQ(lamp_from_string("840"), Lamp::tl84);
  EXPECT_EQ(lamp_from_string("Cwf"), Lamp::cwf);
  EXPECT_EQ(lamp_from_string("F2"), Lamp::cwf);
  EXPECT_EQ(lamp_from_string("d65"), Lamp::d65);
  EXPECT_EQ(lamp_from_string("uv"), Lamp::uv);
  try {
    lamp_from_string("D50");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::bad_parameter);
  }
}

TEST(SimLamps, SpectraAreColordsCieTablesAndAUvBand) {
  const Scene scene(quick(), std::make_shared<SimClock>());
  // CIE F2 and F11 have their mercury lines at 435 and 545 nm; D65 is smooth; A rises to the red.
  const Spectrum& f11 = scene.lamp_spectrum(Lamp::tl84);
  EXPECT_DOUBLE_EQ(*std::max_element(f11.values.begin(), f11.values.end()), 1.0);
  EXPECT_GT(f11.at(545), 5 * f11.at(525));
  EXPECT_GT(scene.lamp_spectrum(Lamp::cwf).at(435), 2 * scene.lamp_spectrum(Lamp::cwf).at(455));
  const Spectrum& a = scene.lamp_spectrum(Lamp::a);
  EXPECT_GT(a.at(700), 2 * a.at(450)) << a.start_nm << " " << a.step_nm << " " << a.values.size();
  const Spectrum& uv = scene.lamp_spectrum(Lamp::uv);
  EXPECT_GT(uv.at(365), 0.9);
  EXPECT_GT(uv.at(370), 0.9);
  EXPECT_LT(uv.at(550), 1e-3);
  // White points from colord's data (independently: CIE 15 tables) — D65 x,y = 0.3127, 0.3290.
  const auto xyz = analysis::emission_to_xyz(as_set(scene.lamp_spectrum(Lamp::d65)),
                                             analysis::Observer::cie1931_2deg, 0)[0];
  const auto xy = analysis::xyz_to_xyy(xyz);
  EXPECT_NEAR(xy.x, 0.3127, 2e-4);
  EXPECT_NEAR(xy.y, 0.3290, 2e-4);
}

TEST(SimRadiance, GreyFloorRadianceIntegratesToTheFieldLuminance) {
  SceneConfig cfg = quick();
  cfg.lamps_on_at_start = {Lamp::d65, Lamp::tl84};
  cfg.dimmer_percent_at_start = 60;
  const Scene scene(cfg, std::make_shared<SimClock>());
  const Spectrum grey{380, 350, {0.30, 0.30}};
  for (auto [x, y] : {std::pair{600.0, 30.0}, std::pair{100.0, 400.0}}) {
    const auto L = analysis::emission_to_xyz(as_set(scene.spectral_radiance(x, y, grey)),
                                             analysis::Observer::cie1931_2deg, 683.0)[0];
    // The radiance grid stops at 730 nm, which loses < 0.1 % of the photopic integral.
    EXPECT_NEAR(L.Y, scene.floor_luminance_at(x, y), 2e-3 * L.Y) << x << "," << y;
  }
  const Spectrum w = scene.white_radiance(600, 30);
  EXPECT_NEAR(w.at(560) * 0.3, scene.spectral_radiance(600, 30, grey).at(560), 1e-12);
}

TEST(SimClock, ScalesRealTime) {
  const SimClock fast(1000.0);
  EXPECT_DOUBLE_EQ(fast.time_scale(), 1000.0);
  EXPECT_EQ(fast.to_real(1.0), std::chrono::milliseconds(1));
  EXPECT_EQ(fast.to_real(-5.0), std::chrono::steady_clock::duration::zero());
  const double t0 = fast.now();
  fast.sleep_for(20.0);  // 20 ms real
  EXPECT_GE(fast.now() - t0, 20.0);
  EXPECT_THROW(SimClock(0.0), Error);
  EXPECT_THROW(SimClock(-1.0), Error);
}

TEST(SimDeterminism, StreamsAreSeededPerConsumer) {
  const Scene a(quick(5), std::make_shared<SimClock>());
  const Scene b(quick(5), std::make_shared<SimClock>());
  const Scene c(quick(6), std::make_shared<SimClock>());
  EXPECT_EQ(a.seed(), 5u);
  EXPECT_EQ(a.stream_seed("ls110"), b.stream_seed("ls110"));
  EXPECT_NE(a.stream_seed("ls110"), a.stream_seed("spectrolino"));
  EXPECT_NE(a.stream_seed("ls110"), c.stream_seed("ls110"));
  auto ra = a.rng_stream("camera");
  auto rb = b.rng_stream("camera");
  EXPECT_EQ(ra(), rb());
}

TEST(SimSpectrolino, NoisyReflectanceHasTheStatedRepeatability) {
  const Scene scene(quick(), std::make_shared<SimClock>());
  auto rng = scene.rng_stream("spectrolino");
  const Spectrum& tile = scene.white_tile();
  EXPECT_NEAR(tile.at(560), 0.87, 0.02);
  double sum = 0, sum2 = 0;
  const int n = 2000;
  for (int i = 0; i < n; ++i) {
    const double v = scene.noisy_reflectance(tile, rng).at(560);
    sum += v;
    sum2 += v * v;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  const double expected = std::hypot(0.001 * tile.at(560), 0.0005 + 0.001 * tile.at(560));
  EXPECT_NEAR(mean, tile.at(560), 4 * expected / std::sqrt(n));
  EXPECT_NEAR(sd, expected, 0.1 * expected);
  EXPECT_LT(scene.transmission_sample().at(420), 0.1);
  EXPECT_GT(scene.transmission_sample().at(700), 0.8);
}

TEST(SimThreadSafety, ConcurrentWritersAndReadersSeeConsistentState) {
  SceneConfig cfg = quick();
  Scene scene(cfg, std::make_shared<SimClock>());
  std::thread writer([&] {
    for (int i = 0; i < 2000; ++i) {
      scene.set_dimmer(i % 101);
      scene.set_lamp(Lamp::d65, i % 2 == 0);
    }
  });
  double last = 0;
  for (int i = 0; i < 2000; ++i) last = scene.floor_luminance(i % 8, i % 20);
  writer.join();
  EXPECT_GE(last, 0.0);
  EXPECT_GE(scene.state_version(), 4000u);
}

}  // namespace
}  // namespace colorlab::sim
