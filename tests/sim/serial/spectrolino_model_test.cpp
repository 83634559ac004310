// Golden byte transcripts of the simulated Spectrolino / SpectroScan T (no pty): exact answers to the
// sequence Argyll sends (instrument-protocols.md §5.4), every error table entry the model produces,
// measurement truth against the Scene and colorimetry, and determinism for a seed.
#include <gtest/gtest.h>

#include <memory>

#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/sim/clock.hpp"
#include "colorlab/sim/scene.hpp"
#include "colorlab/sim/spectrolino_model.hpp"

namespace sp = colorlab::wire::spectrolino;
using colorlab::sim::Scene;
using colorlab::sim::SceneConfig;
using colorlab::sim::SimClock;
using colorlab::sim::SpectrolinoConfig;
using colorlab::sim::SpectrolinoModel;

namespace {

struct Fixture {
  std::shared_ptr<SimClock> clock = std::make_shared<SimClock>(1.0);
  std::unique_ptr<Scene> scene;
  std::unique_ptr<SpectrolinoModel> model;
  explicit Fixture(bool table, std::uint64_t seed = 3) {
    SceneConfig sc;
    sc.seed = 11;
    sc.lamps_on_at_start = {colorlab::sim::Lamp::d65};
    scene = std::make_unique<Scene>(sc, clock);
    SpectrolinoConfig c;
    c.table = table;
    model = std::make_unique<SpectrolinoModel>(*scene, c, seed);
  }
  std::string q(const std::string& req) { return model->handle(req + "\r\n").bytes; }
};

std::string pad(const std::string& hex_text, std::size_t len) { return hex_text + std::string(2 * len - hex_text.size(), '0'); }

std::string u16(unsigned v) {
  char b[16];
  std::snprintf(b, sizeof b, "%02X%02X", v & 0xFFu, (v >> 8) & 0xFFu);
  return b;
}

std::array<double, 3> xyz_d50(const sp::Spectrum& s) {
  namespace an = colorlab::analysis;
  an::ReflectanceIntegrator integ(an::load_illuminant("D50"), an::load_observer(an::Observer::cie1931_2deg),
                                  an::uniform_grid(380, 730, 10));
  Eigen::RowVectorXd r(36);
  for (int i = 0; i < 36; ++i) r(i) = s[static_cast<std::size_t>(i)];
  auto x = integ.xyz(r);
  return {x.X, x.Y, x.Z};
}

}  // namespace

TEST(SimSpectrolinoModel, ArgyllStandAloneInitTranscript) {
  Fixture f(false);
  EXPECT_EQ(f.q(";D024"), ":2604\r\n");
  EXPECT_EQ(f.q(";00"), ":0B0101030001\r\n");
  EXPECT_EQ(f.q(";4DCF"), ":1F0000\r\n");
  auto speed = f.model->handle(";4D27\r\n");
  EXPECT_EQ(speed.bytes, ":1F0000\r\n");
  EXPECT_EQ(speed.baud_after, 9600);
  EXPECT_EQ(f.q(";D030"), ":2604\r\n");
  std::string name = pad("5370656374726F6C696E6F", 18);
  EXPECT_EQ(f.q(";2B"), ":31" + name + "3930" + "6400" + "CF07" + "0600" + "0F00" + "0C00" + "0000" + "02" +
                            "7C01" + "2400" + "0A00" + "\r\n");
  EXPECT_EQ(f.q(";5A010405"), ":1F0000\r\n");
  EXPECT_EQ(f.q(";4A"), ":1F0000\r\n");
  EXPECT_EQ(f.q(";B5"), ":B6" + name + "20" + "33362E37372E3931" + "39300000" + pad("56312E3230", 12) +
                            std::string(32, '0') + "\r\n");
  EXPECT_EQ(f.q(";1601010300"), ":1F0000\r\n");
  EXPECT_EQ(f.q(";33000000"), ":1F0000\r\n");
  EXPECT_EQ(f.q(";07"), ":120009\r\n");
  EXPECT_EQ(f.q(";33000100"), ":1F0000\r\n");
  EXPECT_EQ(f.q(";4D9B"), ":1F0000\r\n");
  auto white = sp::WhiteReferenceAnswer::decode(sp::unframe_answer(f.q(";B301")));
  EXPECT_EQ(white.name, "WT12345");
  EXPECT_NEAR(white.reference[20], f.scene->white_tile().values[20], 1e-6);
}

TEST(SimSpectrolinoModel, CalibrateThenMeasurePatchMatchesSceneTruth) {
  Fixture f(false);
  EXPECT_EQ(f.q(";20"), ":2537\r\n");  // no white calibration yet
  f.model->place_on_patch(0);
  EXPECT_EQ(f.q(";220907"), ":250E\r\n");  // not on the tile
  f.model->place_on_tile();
  EXPECT_EQ(f.q(";220907"), ":2513\r\n");
  EXPECT_EQ(f.q(";07"), ":120209\r\n");
  int patch = *f.scene->chart().index_of("D4");
  f.model->place_on_patch(patch);
  EXPECT_EQ(f.q(";20"), ":2500\r\n");
  EXPECT_EQ(f.q(";07"), ":120109\r\n");
  auto spec = sp::SpecParameterAnswer::decode(sp::unframe_answer(f.q(";B80900")));
  EXPECT_EQ(spec.ref_valid, 1);
  const auto truth = f.scene->chart().patches[static_cast<std::size_t>(patch)].reflectance.resampled(380, 10, 36);
  for (std::size_t i = 0; i < 36; ++i) EXPECT_NEAR(spec.spectrum[i], truth.values[i], 0.01) << "band " << i;
  auto xyz = sp::CParameterAnswer::decode(sp::unframe_answer(f.q(";BA0904")));
  EXPECT_EQ(xyz.illuminant, sp::Illuminant::D50);
  sp::Spectrum t{};
  for (std::size_t i = 0; i < 36; ++i) t[i] = static_cast<float>(truth.values[i]);
  auto want = xyz_d50(t);
  auto exact = xyz_d50(spec.spectrum);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(xyz.values[static_cast<std::size_t>(k)], exact[static_cast<std::size_t>(k)], 1e-3);  // same spectrum
    EXPECT_NEAR(xyz.values[static_cast<std::size_t>(k)], want[static_cast<std::size_t>(k)], 0.6);    // within noise
  }
}

TEST(SimSpectrolinoModel, ErrorTables) {
  Fixture f(false);
  f.model->place_on_tile();
  EXPECT_EQ(f.q("00"), ":2601\r\n");             // no start character
  EXPECT_EQ(f.q(";0G"), ":2602\r\n");            // illegal character
  EXPECT_EQ(f.q(";00FF"), ":2603\r\n");          // wrong record length
  EXPECT_EQ(f.q(";FE"), ":2604\r\n");            // unknown message
  EXPECT_EQ(f.q(";D000"), ":2604\r\n");          // no table on a stand-alone Spectrolino
  EXPECT_EQ(f.q(";1604010300"), ":1F0100\r\n");  // bad density standard -> remote error bit 0001
  EXPECT_EQ(f.q(";1601010700"), ":1F0400\r\n");  // illuminant 07 does not exist -> 0004
  EXPECT_EQ(f.q(";220908"), ":2535\r\n");        // emission calibration outside emission mode
  EXPECT_EQ(f.q(";4D9D"), ":1F0000\r\n");
  EXPECT_EQ(f.q(";20"), ":2537\r\n");  // emission without its calibration
  EXPECT_EQ(f.q(";220908"), ":2534\r\n");
  EXPECT_EQ(f.q(";4D9B"), ":1F0000\r\n");
  f.model->set_forced_exec_error(sp::exec_err::LampFailure, true);
  EXPECT_EQ(f.q(";220907"), ":2504\r\n");
  EXPECT_EQ(f.q(";29"), ":2F04\r\n");
  EXPECT_EQ(f.q(";220907"), ":2513\r\n");  // once
  f.model->set_forced_exec_error(sp::exec_err::MeasDisabled, false);
  EXPECT_EQ(f.q(";20"), ":2509\r\n");
  EXPECT_EQ(f.q(";20"), ":2509\r\n");
  f.model->set_forced_exec_error(std::nullopt, false);
  EXPECT_EQ(f.q(";20"), ":2500\r\n");
  f.model->expire_calibration();
  EXPECT_EQ(f.q(";20"), ":2537\r\n");
  EXPECT_EQ(f.q(";B80900").substr(0, 7), ":B90900");
}

TEST(SimSpectrolinoModel, SpectroScanTableTranscript) {
  Fixture f(true);
  EXPECT_EQ(f.q(";D024"), ":D18310\r\n");  // online
  EXPECT_EQ(f.q(";D030"), ":D190" + pad("5370656374726F5363616E54", 18) + "\r\n");
  EXPECT_EQ(f.q(";D00A"), ":D18000\r\n");
  EXPECT_EQ(f.q(";D010"), ":D18000\r\n");
  EXPECT_EQ(f.q(";D02102"), ":D18000\r\n");
  auto sp_speed = f.model->handle(";D02008\r\n");
  EXPECT_EQ(sp_speed.bytes, ":D18000\r\n");
  EXPECT_EQ(sp_speed.baud_after, 19200);
  EXPECT_EQ(f.q(";D02099"), ":D18002\r\n");  // no such speed
  EXPECT_EQ(f.q(";D00B"), ":D18000\r\n");
  EXPECT_EQ(f.q(";D031"), ":D191" + std::string("31D40000") + "\r\n");  // 54321
  EXPECT_EQ(f.q(";D033"), ":D193" + u16(20) + u16(9) + u16(2000) + "\r\n");
  // White calibration on tile 1 the way Argyll does it.
  EXPECT_EQ(f.q(";D00600"), ":D18000\r\n");
  EXPECT_EQ(f.q(";220907"), ":250E\r\n");  // head still up
  EXPECT_EQ(f.q(";D004"), ":D18000\r\n");
  EXPECT_EQ(f.q(";220907"), ":2513\r\n");
  EXPECT_EQ(f.q(";D003"), ":D18000\r\n");
  EXPECT_EQ(f.q(";D00501"), ":D18101" + std::string("0000") + u16(2980) + u16(200) + "00\r\n");
  // Paper, offline, range, status.
  EXPECT_EQ(f.q(";D012"), ":D18000\r\n");
  EXPECT_EQ(f.q(";D024"), ":D18390\r\n");
  EXPECT_EQ(f.q(";D011"), ":D18000\r\n");
  EXPECT_EQ(f.q(";D00000" + u16(0) + u16(0)), ":D18001\r\n");  // offline
  EXPECT_EQ(f.q(";D010"), ":D18000\r\n");
  EXPECT_EQ(f.q(";D00000" + u16(3101) + u16(0)), ":D18002\r\n");  // out of range
  EXPECT_EQ(f.q(";D0FF"), ":D18005\r\n");
  EXPECT_EQ(f.q(";D02610"), ":D18000\r\n");
  EXPECT_EQ(f.q(";D028"), ":D18310\r\n");
  EXPECT_EQ(f.q(";D02710"), ":D18000\r\n");
  EXPECT_EQ(f.q(";D00E01"), ":D18009\r\n");  // transmission command in reflection mode
  EXPECT_EQ(f.q(";D013"), ":D18000\r\n");
  // MoveAndMeasure onto a patch returns the spectrum answer.
  const auto& p = f.scene->chart().patches[5];
  auto x = static_cast<unsigned>(std::lround((f.model->config().chart_origin_x_mm + p.x_mm + p.size_mm / 2) * 10));
  auto y = static_cast<unsigned>(std::lround((f.model->config().chart_origin_y_mm + p.y_mm + p.size_mm / 2) * 10));
  auto m = f.model->handle(";D007" + u16(x) + u16(y) + "\r\n");
  auto spec = sp::SpectrumAnswer::decode(sp::unframe_answer(m.bytes));
  auto truth = p.reflectance.resampled(380, 10, 36);
  for (std::size_t i = 0; i < 36; ++i) EXPECT_NEAR(spec.spectrum[i], truth.values[i], 0.01);
  EXPECT_GT(m.device_seconds, f.model->timing().measure_s + 2 * f.model->timing().head_s);
  EXPECT_EQ(f.q(";D0070000FFFF"), ":D18002\r\n");
  // Transmission mode: moves are refused, the filter sample is measured after calibration.
  EXPECT_EQ(f.q(";D00D01"), ":D18000\r\n");
  EXPECT_EQ(f.q(";D002"), ":D1800A\r\n");
  EXPECT_EQ(f.q(";220907"), ":2513\r\n");
  EXPECT_EQ(f.q(";20"), ":2500\r\n");
  auto t = sp::SpecParameterAnswer::decode(sp::unframe_answer(f.q(";B80900")));
  auto ts = f.scene->transmission_sample();
  for (std::size_t i = 0; i < 36; ++i) EXPECT_NEAR(t.spectrum[i], ts.values[i], 0.01);
}

TEST(SimSpectrolinoModel, MoveTimesFollowTheMotionProfile) {
  Fixture f(true);
  // 250 mm/s, 1000 mm/s^2: a 300 mm move is 300/250 + 250/1000 = 1.45 s; a 10 mm move 2*sqrt(0.01) = 0.2 s.
  EXPECT_NEAR(f.model->move_seconds(300, 0), 1.45, 1e-9);
  EXPECT_NEAR(f.model->move_seconds(10, 0), 0.2, 1e-9);
  EXPECT_NEAR(f.model->move_seconds(300, 10), 1.45, 1e-9);  // axes move at once
}

TEST(SimSpectrolinoModel, SameSeedSameBytesOtherSeedOtherBytes) {
  auto run = [](std::uint64_t seed) {
    Fixture f(false, seed);
    std::string all;
    f.model->place_on_tile();
    all += f.q(";220907");
    f.model->place_on_patch(17);
    for (int i = 0; i < 3; ++i) {
      all += f.q(";20");
      all += f.q(";B80900");
      all += f.q(";BA0904");
    }
    return all;
  };
  EXPECT_EQ(run(5), run(5));
  EXPECT_NE(run(5), run(6));
}
