// The blob API's rules (RFC 9110 Range and If-None-Match) and the daemon's start-up check of the
// image store: a file without a row, a row whose file is gone, one whose file has other bytes, a
// partial write — each reported, none deleted; a PNG preview of a float mosaic.
#include <fstream>
#include <set>
#include <thread>
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>

#include "colorlab/api/conditional.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/daemon/blob_service.hpp"
#include "colorlab/daemon/config.hpp"
#include "colorlab/store/blob_index.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::daemon::BlobService;
using colorlab::daemon::ByteRange;
using colorlab::daemon::none_match_hits;
using colorlab::daemon::parse_byte_range;
using colorlab::testing::TempDir;
using nlohmann::json;

namespace {

json run_check(boost::asio::io_context& io, BlobService& blobs) {
  blobs.start_check();
  // The check's thread posts its report to the io thread: run it until the report is in.
  for (int i = 0; i < 2000 && blobs.check_report().value("state", "") == "running"; ++i) {
    io.restart();
    io.run_for(std::chrono::milliseconds(10));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return blobs.check_report();
}

std::set<std::string> shas(const json& list) {
  std::set<std::string> out;
  for (const auto& e : list) out.insert(e["sha256"].get<std::string>());
  return out;
}

}  // namespace

TEST(ByteRanges, OneRangeIsServedPartially) {
  auto r = parse_byte_range("bytes=0-99", 1000);
  EXPECT_EQ(r.kind, ByteRange::Kind::partial);
  EXPECT_EQ(r.first, 0u);
  EXPECT_EQ(r.last, 99u);
  r = parse_byte_range("bytes=990-", 1000);
  EXPECT_EQ(r.first, 990u);
  EXPECT_EQ(r.last, 999u);
  r = parse_byte_range("bytes=-10", 1000);  // the last ten
  EXPECT_EQ(r.first, 990u);
  EXPECT_EQ(r.last, 999u);
  r = parse_byte_range("bytes=-5000", 1000);  // more than there is: all of it
  EXPECT_EQ(r.first, 0u);
  EXPECT_EQ(r.last, 999u);
  r = parse_byte_range("bytes=500-5000", 1000);  // the end clipped to the last byte
  EXPECT_EQ(r.last, 999u);
  r = parse_byte_range("Bytes=1-1", 1000);  // the unit is case-insensitive
  EXPECT_EQ(r.kind, ByteRange::Kind::partial);
}

TEST(ByteRanges, BeyondTheEndIsUnsatisfiableAndTheRestIsServedWhole) {
  EXPECT_EQ(parse_byte_range("bytes=1000-", 1000).kind, ByteRange::Kind::unsatisfiable);
  EXPECT_EQ(parse_byte_range("bytes=5000-6000", 1000).kind, ByteRange::Kind::unsatisfiable);
  EXPECT_EQ(parse_byte_range("bytes=-0", 1000).kind, ByteRange::Kind::unsatisfiable);
  EXPECT_EQ(parse_byte_range("bytes=0-", 0).kind, ByteRange::Kind::unsatisfiable);
  for (const char* whole : {"bytes=0-1,5-6", "items=0-1", "bytes=9-3", "bytes=a-b", "bytes=", "bytes=--1", "bytes=99999999999999999999-"}) {
    EXPECT_EQ(parse_byte_range(whole, 1000).kind, ByteRange::Kind::whole) << whole;
  }
}

TEST(EntityTags, IfNoneMatchComparesWeakly) {
  const std::string tag = "\"ab12\"";
  EXPECT_TRUE(none_match_hits("\"ab12\"", tag));
  EXPECT_TRUE(none_match_hits("W/\"ab12\"", tag));
  EXPECT_TRUE(none_match_hits("\"x\", \"ab12\"", tag));
  EXPECT_TRUE(none_match_hits("*", tag));
  EXPECT_FALSE(none_match_hits("\"ab1\"", tag));
  EXPECT_FALSE(none_match_hits("", tag));
}

TEST(BlobCheck, ReportsOrphansMissingAndDamagedFilesAndDeletesNothing) {
  TempDir dir;
  boost::asio::io_context io;
  colorlab::store::Store store(dir / "colorlab.db");
  BlobService blobs(io, store, dir.path(), {});
  auto keep = [&](const std::string& s) {
    return blobs.keep_bytes("n", "raw", "application/octet-stream", json::object(),
                            std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()));
  };
  auto intact = keep("intact");
  auto gone = keep("gone");
  auto damaged = keep("damaged");
  auto orphan = keep("no row: the daemon died between the file and its step");
  // Rows for three of them, as a committed step makes them.
  colorlab::store::NewRun r;
  r.campaign = "frame-average";
  r.params = json::object();
  r.instruments = json::array();
  r.script_sha256 = "s";
  r.script_source = "x";
  auto e = store.create_execution(r).execution;
  colorlab::store::StepRecord step;
  step.step = "s";
  for (const auto& b : {intact, gone, damaged}) {
    step.blobs.push_back({b.sha256, b.sha256.substr(0, 8), b.kind, b.media_type, b.size, b.meta});
  }
  store.commit_step(e, step);
  std::filesystem::remove(blobs.files().path_of(gone.sha256));
  std::ofstream(blobs.files().path_of(damaged.sha256), std::ios::binary | std::ios::trunc) << "DAMAGED";  // same length, other bytes
  std::ofstream(blobs.files().path_of(intact.sha256).parent_path() / ".tmp-99-0") << "half";

  // The check judges files as they were when it started: an orphan written before it.
  std::filesystem::last_write_time(blobs.files().path_of(orphan.sha256),
                                   std::filesystem::file_time_type::clock::now() - std::chrono::seconds(60));
  const json report = run_check(io, blobs);
  ASSERT_EQ(report["state"], "done") << report.dump();
  EXPECT_FALSE(report["ok"]);
  EXPECT_EQ(shas(report["orphans"]), std::set<std::string>{orphan.sha256});
  EXPECT_EQ(shas(report["missing"]), std::set<std::string>{gone.sha256});
  EXPECT_EQ(shas(report["mismatched"]), std::set<std::string>{damaged.sha256});
  ASSERT_EQ(report["partial"].size(), 1u);
  // Nothing was deleted: the orphan and the damaged file are still there.
  EXPECT_TRUE(std::filesystem::exists(blobs.files().path_of(orphan.sha256)));
  EXPECT_TRUE(std::filesystem::exists(blobs.files().path_of(damaged.sha256)));
  // And the event log says so.
  auto events = store.events(0, 100, std::string("blobs"));
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].payload["event"], "check");
  EXPECT_EQ(events[0].payload["orphans_count"], 1);
  EXPECT_EQ(events[0].payload["missing_count"], 1);
}

TEST(BlobCheck, AnIntactStoreIsOk) {
  TempDir dir;
  boost::asio::io_context io;
  colorlab::store::Store store(dir / "colorlab.db");
  BlobService blobs(io, store, dir.path(), {});
  const json report = run_check(io, blobs);
  EXPECT_EQ(report["state"], "done");
  EXPECT_TRUE(report["ok"]);
  EXPECT_EQ(report["files"], 0);
}

TEST(BlobPreview, AFloatMosaicBecomesAHalfSizePng) {
  TempDir dir;
  boost::asio::io_context io;
  colorlab::store::Store store(dir / "colorlab.db");
  BlobService blobs(io, store, dir.path(), {});
  const int h = 40, w = 60;
  std::vector<float> mosaic(static_cast<std::size_t>(h * w));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) mosaic[static_cast<std::size_t>(y * w + x)] = 256.f + 10.f * x + ((x % 2 == 0 && y % 2 == 0) ? 500.f : 0.f);
  }
  auto average = blobs.keep_bytes("average", "average", colorlab::campaigns::kArrayMediaType,
                                  json{{"dtype", "<f4"}, {"shape", {h, w}}, {"cfa", "RGGB"}, {"black_level", 256}},
                                  std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(mosaic.data()), mosaic.size() * 4));
  auto preview = blobs.keep_preview("average.png", average);
  EXPECT_EQ(preview.kind, "preview");
  EXPECT_EQ(preview.media_type, "image/png");
  EXPECT_EQ(preview.meta["preview_of"], average.sha256);
  std::ifstream in(blobs.files().path_of(preview.sha256), std::ios::binary);
  std::string png((std::istreambuf_iterator<char>(in)), {});
  ASSERT_GT(png.size(), 24u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  auto be32 = [&](std::size_t at) {
    return (static_cast<unsigned char>(png[at]) << 24) | (static_cast<unsigned char>(png[at + 1]) << 16) |
           (static_cast<unsigned char>(png[at + 2]) << 8) | static_cast<unsigned char>(png[at + 3]);
  };
  EXPECT_EQ(be32(16), w / 2);               // IHDR width
  EXPECT_EQ(be32(20), h / 2);               // IHDR height
  EXPECT_EQ(static_cast<int>(png[25]), 2);  // colour type 2: RGB
}

TEST(BlobRetention, RemovesOnlyOldBlobsOfKindsNotKeptAndSaysSo) {
  TempDir dir;
  boost::asio::io_context io;
  colorlab::store::Store store(dir / "colorlab.db");
  colorlab::daemon::BlobConfig config;
  config.retention_days = 1.0 / 86400;  // one second
  config.keep = {"average"};
  BlobService blobs(io, store, dir.path(), config);
  auto keep = [&](const std::string& s, const std::string& kind) {
    return blobs.keep_bytes(kind, kind, "application/octet-stream", json::object(),
                            std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()));
  };
  auto raw = keep("a raw", "raw"), average = keep("an average", "average");
  colorlab::store::NewRun r;
  r.campaign = "frame-average";
  r.params = json::object();
  r.instruments = json::array();
  r.script_sha256 = "s";
  r.script_source = "x";
  auto e = store.create_execution(r).execution;
  colorlab::store::StepRecord step;
  step.step = "s";
  for (const auto& b : {raw, average}) step.blobs.push_back({b.sha256, b.name, b.kind, b.media_type, b.size, b.meta});
  store.commit_step(e, step);

  // Nothing is a second old yet.
  EXPECT_EQ(blobs.apply_retention(false)["count"], 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  const json dry = blobs.apply_retention(true);
  EXPECT_EQ(dry["count"], 1);
  EXPECT_TRUE(std::filesystem::exists(blobs.files().path_of(raw.sha256)));  // a dry run removes nothing
  const json done = blobs.apply_retention(false);
  ASSERT_EQ(done["count"], 1);
  EXPECT_EQ(done["removed"][0]["sha256"], raw.sha256);
  EXPECT_EQ(done["bytes"], raw.size);
  EXPECT_FALSE(std::filesystem::exists(blobs.files().path_of(raw.sha256)));
  EXPECT_TRUE(std::filesystem::exists(blobs.files().path_of(average.sha256)));  // a kind retention keeps
  EXPECT_EQ(colorlab::store::BlobIndex(store).of_run(e.run_id).size(), 1u);
  auto events = store.events(0, 100, std::string("blobs"));
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].payload["event"], "retention");
  EXPECT_EQ(events[0].payload["count"], 1);
}

TEST(BlobConfigFile, TheBlobsSectionIsReadAndCheckedWithItsLine) {
  TempDir dir;
  std::ofstream(dir / "good.toml") << "[blobs]\nretention_days = 30\nkeep = [\"raw\", \"average\"]\nverify_hashes = false\n";
  auto c = colorlab::daemon::load_config(dir / "good.toml");
  EXPECT_EQ(c.blobs.retention_days, 30);
  EXPECT_EQ(c.blobs.keep, (std::vector<std::string>{"raw", "average"}));
  EXPECT_FALSE(c.blobs.verify_hashes);
  std::ofstream(dir / "bad.toml") << "[blobs]\nretention_days = 1\nkeep = [\"frames\"]\n";
  try {
    colorlab::daemon::load_config(dir / "bad.toml");
    FAIL() << "an unknown kind was accepted";
  } catch (const colorlab::Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.toml:3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("blobs.keep"), std::string::npos) << e.what();
  }
}
