// The simulated lab's tethered DSLR through the driver colorlabd builds for it: colorlab-sim as a
// process, the factory's `simdslr` instrument over the socket, real DNGs through LibRaw. The raw
// counts are held to the simulator's own truth for each shot (CameraModel's noiseless patch means,
// within the per-pixel noise the model says it injects), not to an earlier output of this code.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <thread>

#include <boost/asio/co_spawn.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/use_future.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/camera/camera_instrument.hpp"
#include "sim_lab_process.hpp"

namespace cam = colorlab::drivers::camera;
using colorlab::Error;
using colorlab::ErrorClass;
using colorlab::testing::SimLabProcess;
using nlohmann::json;

namespace {

constexpr const char* kSmallDslr = "[dslr]\nsize = [640, 428]\n";

struct Rig {
  SimLabProcess sim;
  boost::asio::io_context io;
  std::shared_ptr<cam::CameraInstrument> instrument;

  explicit Rig(const std::string& toml = kSmallDslr, json options = json::object()) : sim(toml) {
    auto config = sim.config_for("simdslr");
    config.options.update(options);
    instrument = std::dynamic_pointer_cast<cam::CameraInstrument>(colorlab::drivers::make_instrument(io.get_executor(), config));
    if (!instrument) throw std::runtime_error("the factory's simdslr is not a CameraInstrument");
  }

  // Through the Instrument contract, as the daemon connects it.
  void connect() {
    auto done = boost::asio::co_spawn(io, instrument->connect(), boost::asio::use_future);
    io.restart();
    io.run();
    done.get();
  }
  cam::Camera& camera() { return instrument->camera(); }

  // Lamps just switched on warm up (Scene: from 85 % with a 120 s time constant); a frame rendered
  // meanwhile would not belong to one lamp state.
  void wait_until_warm() {
    for (int i = 0; i < 400; ++i) {
      const json t = sim.control({{"cmd", "truth"}});
      bool warm = true;
      for (const auto& [lamp, f] : t["warmup"].items()) warm = warm && f.get<double>() > 0.99999;
      if (warm) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(25));
    }
    FAIL() << "the lamps never warmed up";
  }
};

struct Frames {
  std::vector<cam::OwnedRawImage> images;
  cam::CaptureReport report;
};

Frames capture(cam::Camera& camera, std::size_t n) {
  Frames f;
  f.report = camera.capture(n, [&](const cam::RawImage& img) { f.images.push_back(cam::OwnedRawImage::copy_of(img)); }).get();
  return f;
}

struct PatchCheck {
  int compared = 0;
  int failed = 0;
  std::string first_failure;
};

// Every patch without dust, per CFA colour, defective pixels left out: the mean raw count against
// the simulator's noiseless mean, within 5 standard errors of the noise the model injects.
PatchCheck compare_with_truth(const cam::RawImage& img, const json& truth) {
  std::set<std::pair<int, int>> defects;
  for (const auto& d : truth["defects"]) defects.emplace(d[0].get<int>(), d[1].get<int>());
  std::set<int> dusty;
  for (const auto& p : truth["dust_patches"]) dusty.insert(p.get<int>());
  PatchCheck check;
  for (const auto& patch : truth["patches"]) {
    const int index = patch["index"];
    if (dusty.count(index)) continue;
    const auto& r = patch["region"];
    const int x0 = r[0], y0 = r[1], w = r[2], h = r[3];
    std::array<double, 3> sum{};
    std::array<int, 3> n{};
    for (int y = y0; y < y0 + h; ++y) {
      for (int x = x0; x < x0 + w; ++x) {
        if (defects.count({x, y})) continue;
        const auto c = static_cast<int>(img.cfa.at(static_cast<std::size_t>(y), static_cast<std::size_t>(x)));
        sum[static_cast<std::size_t>(c)] += img.at(static_cast<std::size_t>(x), static_cast<std::size_t>(y));
        ++n[static_cast<std::size_t>(c)];
      }
    }
    for (std::size_t c = 0; c < 3; ++c) {
      const double expected = patch["mean"][c];
      const double sigma = patch["pixel_sigma"][c];
      if (n[c] < 16 || expected + 5 * sigma >= truth["white_level"].get<double>()) continue;  // clipped: no mean to compare
      const double got = sum[c] / n[c];
      const double tolerance = 5 * sigma / std::sqrt(n[c]);
      ++check.compared;
      if (std::abs(got - expected) > tolerance) {
        if (!check.failed++) {
          check.first_failure = "patch " + std::to_string(index) + " channel " + std::to_string(c) + ": " + std::to_string(got) +
                                " vs truth " + std::to_string(expected) + " ± " + std::to_string(tolerance);
        }
      }
    }
  }
  return check;
}

json shot_truth(SimLabProcess& sim, const std::filesystem::path& raw) {
  json t = sim.control({{"cmd", "camera_truth"}, {"instrument", "dslr"}, {"file", raw.filename().string()}});
  EXPECT_EQ(t.value("ok", false), true) << t.dump();
  return t;
}

}  // namespace

TEST(SimDslr, AnnouncedBesideTheOtherInstrumentsAndBuiltByTheFactory) {
  Rig rig;
  rig.connect();
  const auto id = rig.camera().identity();
  EXPECT_EQ(id.serial, "SIM20D0001");
  EXPECT_EQ(id.kind, cam::CameraKind::dslr);
  EXPECT_TRUE(rig.instrument->identity().simulated);
  const auto limits = rig.camera().limits();
  EXPECT_EQ(limits.iso, (std::vector<int>{100, 200, 400, 800, 1600}));
  EXPECT_EQ(limits.shutter_s.size(), 55u);
  EXPECT_EQ(limits.image_formats.size(), 3u);
  json t = rig.sim.control({{"cmd", "truth"}});
  EXPECT_TRUE(t["dslr"]["connected"]);
  EXPECT_EQ(t["dslr"]["connections"], 1);
}

TEST(SimDslr, DecodedRawCountsEqualTheSimulatorsTruthForEveryShot) {
  Rig rig;
  rig.connect();
  rig.wait_until_warm();
  cam::CameraSettings s;
  s.iso = 100;
  s.shutter_s = 1.0 / 60;
  s.aperture_f = 5.6;
  rig.camera().configure(s).get();
  const Frames f = capture(rig.camera(), 3);
  ASSERT_TRUE(f.report.complete()) << (f.report.error ? f.report.error->what() : "");
  ASSERT_EQ(f.images.size(), 3u);
  ASSERT_EQ(f.report.saved_files.size(), 3u);  // raw only
  std::set<std::string> names;
  for (std::size_t k = 0; k < 3; ++k) {
    const auto& raw = f.report.saved_files[k];
    EXPECT_EQ(raw.extension(), ".DNG");
    names.insert(raw.filename().string());
    const json truth = shot_truth(rig.sim, raw);
    EXPECT_DOUBLE_EQ(truth["settings"]["shutter_s"].get<double>(), 1.0 / 60);
    EXPECT_DOUBLE_EQ(truth["settings"]["aperture"].get<double>(), 5.6);
    const auto& img = f.images[k].view();
    ASSERT_EQ(img.width, 640u);
    ASSERT_EQ(img.height, 428u);
    EXPECT_EQ(img.black_level[0], 256);
    const PatchCheck check = compare_with_truth(img, truth);
    EXPECT_GE(check.compared, 300) << "most of the 140 × 3 patch means must be comparable";
    EXPECT_EQ(check.failed, 0) << check.first_failure;
  }
  EXPECT_EQ(names.size(), 3u) << "every shot is its own file";
}

TEST(SimDslr, ALampChangeChangesTheImageAsTheSceneSays) {
  Rig rig;
  rig.connect();
  rig.wait_until_warm();
  const Frames d65 = capture(rig.camera(), 1);
  ASSERT_TRUE(d65.report.complete());
  ASSERT_EQ(rig.sim.control({{"cmd", "lamp"}, {"lamp", "D65"}, {"on", false}})["ok"], true);
  ASSERT_EQ(rig.sim.control({{"cmd", "lamp"}, {"lamp", "A"}, {"on", true}})["ok"], true);
  rig.wait_until_warm();
  const Frames a = capture(rig.camera(), 1);
  ASSERT_TRUE(a.report.complete());

  const json truth_d65 = shot_truth(rig.sim, d65.report.saved_files[0]);
  const json truth_a = shot_truth(rig.sim, a.report.saved_files[0]);
  EXPECT_EQ(compare_with_truth(d65.images[0].view(), truth_d65).failed, 0);
  const PatchCheck under_a = compare_with_truth(a.images[0].view(), truth_a);
  EXPECT_EQ(under_a.failed, 0) << under_a.first_failure;
  // And the comparison tells the two lights apart: the image under A is far from D65's truth.
  const PatchCheck crossed = compare_with_truth(a.images[0].view(), truth_d65);
  EXPECT_GT(crossed.failed, crossed.compared / 2) << "the image did not change with the lamp";
  // Illuminant A is far redder than D65: the truth's R/B of the brightest neutral moves a lot, and
  // the image follows (checked patch by patch above), so the two captures cannot be the same light.
  auto red_over_blue = [](const json& t, int patch) {
    const auto& m = t["patches"][patch]["mean"];
    return (m[0].get<double>() - 256) / (m[2].get<double>() - 256);
  };
  int white = 0;
  for (int p = 0; p < 140; ++p) {
    if (truth_d65["patches"][p]["mean"][1] > truth_d65["patches"][white]["mean"][1]) white = p;
  }
  EXPECT_GT(red_over_blue(truth_a, white), 2 * red_over_blue(truth_d65, white));
}

TEST(SimDslr, RawJpegTiffDeliversTheRawDecodedAndItsThreeSidecars) {
  Rig rig;
  rig.connect();
  cam::CameraSettings s;
  s.image_format = cam::ImageFormat::raw_jpeg_tiff;
  rig.camera().configure(s).get();
  const Frames f = capture(rig.camera(), 2);
  ASSERT_TRUE(f.report.complete()) << (f.report.error ? f.report.error->what() : "");
  ASSERT_EQ(f.report.saved_files.size(), 8u);
  std::multiset<std::string> extensions;
  for (const auto& p : f.report.saved_files) {
    EXPECT_TRUE(std::filesystem::exists(p)) << p;
    EXPECT_GT(std::filesystem::file_size(p), 0u) << p;
    extensions.insert(p.extension().string());
  }
  EXPECT_EQ(extensions.count(".DNG"), 2u);
  EXPECT_EQ(extensions.count(".JPG"), 2u);
  EXPECT_EQ(extensions.count(".TIF"), 4u);  // 8-bit and 16-bit
  EXPECT_EQ(f.report.saved_files[0].extension(), ".DNG") << "the raw comes first, its sidecars after it";
}

TEST(SimDslr, KeepDirCopiesTheFilesAndDeletesThemInTheCamera) {
  colorlab::testing::TempDir keep;
  Rig rig(kSmallDslr, {{"keep_dir", keep.path().string()}});
  rig.connect();
  const Frames f = capture(rig.camera(), 2);
  ASSERT_TRUE(f.report.complete()) << (f.report.error ? f.report.error->what() : "");
  std::filesystem::path camera_dir;
  for (const auto& i : rig.sim.announcement["instruments"]) {
    if (i["kind"] == "simdslr") camera_dir = i["capture_dir"].get<std::string>();
  }
  ASSERT_FALSE(camera_dir.empty());
  for (const auto& p : f.report.saved_files) {
    EXPECT_EQ(p.parent_path(), keep.path());
    EXPECT_TRUE(std::filesystem::exists(p));
    EXPECT_FALSE(std::filesystem::exists(camera_dir / p.filename())) << "left in the camera: " << p.filename();
  }
}

TEST(SimDslr, InjectedFaultsAreTypedErrorsAndTheCameraRecovers) {
  Rig rig(kSmallDslr, {{"capture_timeout_ms", 1500}});
  rig.connect();

  rig.sim.control({{"cmd", "fault"}, {"instrument", "dslr"}, {"faults", {{"capture_timeout", true}}}});
  auto r = capture(rig.camera(), 2).report;
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->cls(), ErrorClass::timeout) << r.error->what();
  EXPECT_EQ(r.delivered, 0u);
  EXPECT_FALSE(r.error->info().transcript.empty());
  r = capture(rig.camera(), 1).report;
  EXPECT_TRUE(r.complete()) << "a timed-out shot leaves the camera usable";

  rig.sim.control({{"cmd", "fault"}, {"instrument", "dslr"}, {"faults", {{"busy", true}}}});
  r = capture(rig.camera(), 1).report;
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->cls(), ErrorClass::conflict) << r.error->what();
  EXPECT_TRUE(r.error->info().retryable);
  EXPECT_TRUE(capture(rig.camera(), 1).report.complete());

  rig.sim.control({{"cmd", "fault"}, {"instrument", "dslr"}, {"faults", {{"malformed_answer", true}}}});
  r = capture(rig.camera(), 1).report;
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->cls(), ErrorClass::protocol_error) << r.error->what();
  EXPECT_EQ(rig.camera().state(), cam::CameraState::fault);
  rig.camera().reconnect(3, std::chrono::milliseconds(10)).get();
  EXPECT_TRUE(capture(rig.camera(), 1).report.complete());

  const json t = rig.sim.control({{"cmd", "truth"}});
  EXPECT_EQ(t["dslr"]["captures_swallowed"], 1);
}

TEST(SimDslr, ACameraThatGoesAwayIsNoCommsUntilItComesBack) {
  Rig rig;
  rig.connect();
  const auto socket = std::filesystem::path(rig.sim.config_for("simdslr").port);
  rig.sim.control({{"cmd", "fault"}, {"instrument", "dslr"}, {"faults", {{"disconnect", true}}}});
  EXPECT_FALSE(std::filesystem::exists(socket)) << "an unplugged camera's socket disappears, so discovery sees it go";
  auto r = capture(rig.camera(), 1).report;
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->cls(), ErrorClass::no_comms) << r.error->what();
  EXPECT_EQ(rig.camera().state(), cam::CameraState::disconnected);
  try {
    rig.camera().connect().get();
    ADD_FAILURE() << "connected to an unplugged camera";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::no_comms) << e.what();
    EXPECT_FALSE(e.hint().empty());
  }
  rig.sim.control({{"cmd", "fault"}, {"instrument", "dslr"}, {"faults", {{"disconnect", false}}}});
  rig.camera().reconnect(3, std::chrono::milliseconds(10)).get();  // same serial: accepted
  EXPECT_TRUE(capture(rig.camera(), 1).report.complete());

  // The simulator itself goes: the socket is gone for good.
  rig.sim.process->signal(SIGKILL);
  rig.sim.process->wait(std::chrono::seconds(10));
  r = capture(rig.camera(), 1).report;
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->cls(), ErrorClass::no_comms) << r.error->what();
}

TEST(SimDslr, ASecondClientIsTurnedAwayWithATypedError) {
  Rig rig;
  rig.connect();
  auto second = colorlab::drivers::make_instrument(rig.io.get_executor(), rig.sim.config_for("simdslr"));
  auto& other = std::dynamic_pointer_cast<cam::CameraInstrument>(second)->camera();
  try {
    other.connect().get();
    ADD_FAILURE() << "two clients hold one camera";
  } catch (const Error& e) {
    EXPECT_EQ(e.cls(), ErrorClass::conflict) << e.what();
  }
  EXPECT_TRUE(capture(rig.camera(), 1).report.complete()) << "the first client keeps the camera";
}
