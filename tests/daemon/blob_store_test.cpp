// The image store's promises (issue 10): files named by the SHA-256 of their bytes (checked with
// sha256sum, an independent tool), durable before any row names them, written once per content;
// a scan that tells blobs from partial writes and strays; the rows a step commits with its journal;
// retention's choice of what has expired.
#include <unistd.h>

#include <fstream>
#include <map>
#include <set>
#include <gtest/gtest.h>

#include "colorlab/core/error.hpp"
#include "colorlab/store/blob_index.hpp"
#include "colorlab/store/blob_store.hpp"
#include "colorlab/store/store.hpp"
#include "colorlab/testing/process.hpp"
#include "colorlab/testing/temp_dir.hpp"

using colorlab::Error;
using colorlab::ErrorClass;
using colorlab::store::BlobIndex;
using colorlab::store::BlobStore;
using colorlab::store::StepBlob;
using colorlab::store::StepRecord;
using colorlab::store::Store;
using colorlab::testing::TempDir;
using nlohmann::json;

namespace {

std::vector<std::uint8_t> bytes_of(const std::string& s) { return {s.begin(), s.end()}; }

std::string read_all(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

std::string sha256sum(const std::filesystem::path& p) {
  return colorlab::testing::shell_output("sha256sum '" + p.string() + "'").substr(0, 64);
}

colorlab::store::ExecutionRecord execution(Store& store) {
  colorlab::store::NewRun r;
  r.campaign = "frame-average";
  r.params = json::object();
  r.simulated = true;
  r.instruments = json::array();
  r.script_sha256 = "s1";
  r.script_source = "x";
  return store.create_execution(r).execution;
}

StepBlob step_blob(const std::string& sha, const std::string& name, const std::string& kind, std::uint64_t size) {
  return StepBlob{sha, name, kind, "application/x-colorlab-array", size, json{{"dtype", "<f4"}, {"shape", {2, 2}}, {"cfa", "RGGB"}}};
}

}  // namespace

TEST(BlobStore, NamesAFileByTheSha256OfItsBytes) {
  TempDir dir;
  BlobStore blobs(dir / "blobs");
  const std::string content = "a frame's bytes\n";
  const std::string sha = blobs.put(bytes_of(content));
  const auto path = blobs.path_of(sha);
  EXPECT_EQ(path, dir / "blobs" / sha.substr(0, 2) / sha.substr(2));
  EXPECT_EQ(read_all(path), content);
  ASSERT_TRUE(colorlab::testing::on_path("sha256sum"));
  EXPECT_EQ(sha256sum(path), sha);
  // The same content again is the same file, written once.
  EXPECT_EQ(blobs.put(bytes_of(content)), sha);
  EXPECT_EQ(blobs.scan().files.size(), 1u);
}

TEST(BlobStore, StoresAFileByContentAndLeavesNoTemporaryFiles) {
  TempDir dir;
  BlobStore blobs(dir / "blobs");
  std::string big(3 * 1024 * 1024 + 17, '\0');
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = static_cast<char>((i * 2654435761u) >> 13);
  {
    std::ofstream out(dir / "IMG_0001.DNG", std::ios::binary);
    out << big;
  }
  const std::string sha = blobs.put_file(dir / "IMG_0001.DNG");
  EXPECT_EQ(sha, sha256sum(dir / "IMG_0001.DNG"));
  EXPECT_EQ(read_all(blobs.path_of(sha)), big);
  EXPECT_EQ(BlobStore::hash_file(blobs.path_of(sha)), sha);
  auto scan = blobs.scan();
  ASSERT_EQ(scan.files.size(), 1u);
  EXPECT_EQ(scan.files[0].sha256, sha);
  EXPECT_EQ(scan.files[0].size, big.size());
  EXPECT_TRUE(scan.strays.empty());
}

TEST(BlobStore, ScanTellsPartialWritesAndStraysFromBlobs) {
  TempDir dir;
  BlobStore blobs(dir / "blobs");
  const std::string sha = blobs.put(bytes_of("x"));
  std::ofstream(blobs.path_of(sha).parent_path() / ".tmp-1-0") << "half";
  std::ofstream(dir / "blobs" / "notes.txt") << "someone's";
  auto scan = blobs.scan();
  ASSERT_EQ(scan.files.size(), 1u);
  ASSERT_EQ(scan.strays.size(), 2u);
  std::set<std::string> why;
  for (const auto& s : scan.strays) why.insert(s.why);
  EXPECT_TRUE(why.count("partial write"));
  EXPECT_TRUE(why.count("not a blob name"));
}

// The start-up check runs while frames are being kept: this process's own temporary file is a write in progress.
TEST(BlobStore, AWriteInProgressOfThisProcessIsNotAPartialOne) {
  TempDir dir;
  BlobStore blobs(dir / "blobs");
  const std::string sha = blobs.put(bytes_of("x"));
  std::ofstream(blobs.path_of(sha).parent_path() / (".tmp-" + std::to_string(::getpid()) + "-7")) << "being written";
  const auto scan = blobs.scan();
  EXPECT_EQ(scan.files.size(), 1u);
  EXPECT_TRUE(scan.strays.empty());
}

TEST(BlobStore, RefusesNamesThatAreNoSha256) {
  TempDir dir;
  BlobStore blobs(dir / "blobs");
  for (const std::string& bad : {std::string("../../etc/passwd"), std::string(64, 'A'), std::string(63, 'a'), std::string(64, 'g')}) {
    try {
      (void)blobs.path_of(bad);
      FAIL() << bad;
    } catch (const Error& e) {
      EXPECT_EQ(e.cls(), ErrorClass::bad_parameter);
    }
  }
}

TEST(BlobIndex, AStepCommitsItsBlobsWithItsJournal) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  BlobStore files(dir / "blobs");
  auto e = execution(store);
  const std::string a = files.put(bytes_of(std::string(16, 'a')));
  const std::string b = files.put(bytes_of(std::string(16, 'b')));
  StepRecord s;
  s.step = "photographing";
  s.progress = 0.5;
  s.journal.push_back({0, "camera.capture", json::array(), json{{"blobs", json::array()}}});
  s.blobs = {step_blob(a, "camera.capture#0/average", "average", 16), step_blob(b, "camera.capture#0/raw", "raw", 16)};
  store.commit_step(e, s);
  // The same content kept again by a later step: one blob row, two references.
  StepRecord s2;
  s2.step = "again";
  s2.journal.push_back({1, "camera.capture", json::array(), nullptr});
  s2.blobs = {step_blob(a, "camera.capture#1/average", "average", 16)};
  store.commit_step(e, s2);

  BlobIndex index(store);
  auto listed = index.of_run(e.run_id);
  ASSERT_EQ(listed.size(), 3u);
  std::map<std::string, colorlab::store::RunBlobRecord> by_name;
  for (const auto& r : listed) by_name[r.name] = r;
  ASSERT_TRUE(by_name.count("camera.capture#0/average"));
  EXPECT_EQ(by_name["camera.capture#0/average"].blob.sha256, a);
  EXPECT_EQ(by_name["camera.capture#0/average"].step, "photographing");
  EXPECT_EQ(by_name["camera.capture#0/raw"].kind, "raw");
  EXPECT_EQ(by_name["camera.capture#0/average"].blob.meta["dtype"], "<f4");
  EXPECT_EQ(index.all().size(), 2u);
  ASSERT_TRUE(index.blob(a).has_value());
  EXPECT_EQ(index.blob(a)->size, 16u);
  EXPECT_EQ(index.blob(a)->media_type, "application/x-colorlab-array");
  EXPECT_FALSE(index.blob(std::string(64, '0')).has_value());
}

TEST(BlobIndex, AStepWhoseBlobNameRepeatsIsRefusedWhole) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  auto e = execution(store);
  const std::string a(64, 'a');
  StepRecord s;
  s.step = "one";
  s.journal.push_back({0, "camera.capture", json::array(), nullptr});
  s.blobs = {step_blob(a, "same", "average", 1)};
  store.commit_step(e, s);
  StepRecord s2;
  s2.step = "two";
  s2.journal.push_back({1, "camera.capture", json::array(), nullptr});
  s2.blobs = {step_blob(a, "same", "average", 1)};
  EXPECT_THROW(store.commit_step(e, s2), Error);
  // Nothing of the refused step is stored: not its journal entry either.
  EXPECT_EQ(store.journal(e.id).size(), 1u);
}

TEST(BlobIndex, RetentionTakesOnlyOldBlobsOfKindsNotKept) {
  TempDir dir;
  Store store(dir / "colorlab.db");
  auto e = execution(store);
  const std::string raw(64, 'a'), avg(64, 'b'), both(64, 'c');
  StepRecord s;
  s.step = "one";
  s.journal.push_back({0, "camera.capture", json::array(), nullptr});
  s.blobs = {step_blob(raw, "raw", "raw", 10), step_blob(avg, "average", "average", 20), step_blob(both, "both-raw", "raw", 30),
             step_blob(both, "both-average", "average", 30)};
  store.commit_step(e, s);
  BlobIndex index(store);
  // Everything is younger than a cutoff in the past.
  EXPECT_TRUE(index.expired("2000-01-01T00:00:00.000Z", {}).empty());
  auto all = index.expired("9999-01-01T00:00:00.000Z", {});
  EXPECT_EQ(all.size(), 3u);
  auto without_average = index.expired("9999-01-01T00:00:00.000Z", {"average"});
  ASSERT_EQ(without_average.size(), 1u);  // a blob one kept kind references stays
  EXPECT_EQ(without_average[0].sha256, raw);
  EXPECT_EQ(without_average[0].references, std::vector<std::string>{e.run_id + "/raw"});
  index.remove(without_average, json{{"event", "retention"}});
  EXPECT_FALSE(index.blob(raw).has_value());
  EXPECT_EQ(index.of_run(e.run_id).size(), 3u);
  auto events = store.events(0, 100, std::string("blobs"));
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].payload["event"], "retention");
}
