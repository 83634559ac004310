// Issue 24: blob references are typed from the campaign to the store. A call keeps its frames through
// the lab's KeepLedger, which hands the references as they were kept (not re-read from the call's
// JSON) to the engine for the step that journals the call.
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "colorlab/campaigns/frame_keeper.hpp"

using colorlab::campaigns::blob_json;
using colorlab::campaigns::FrameKeeper;
using colorlab::campaigns::KeepLedger;
using colorlab::campaigns::KeptBlob;
using nlohmann::json;

namespace {

// Keeps nothing; answers with a reference that names what it was asked.
class NamingKeeper final : public FrameKeeper {
 public:
  KeptBlob keep_bytes(const std::string& name, const std::string& kind, const std::string& media_type, const json& meta,
                      std::span<const std::uint8_t> bytes) override {
    return KeptBlob{"sha-" + name, name, kind, media_type, bytes.size(), meta};
  }
  KeptBlob keep_file(const std::string& name, const std::string& kind, const std::string& media_type, const json& meta,
                     const std::filesystem::path&) override {
    return KeptBlob{"sha-" + name, name, kind, media_type, 7, meta};
  }
  KeptBlob keep_preview(const std::string& name, const KeptBlob& of) override {
    return KeptBlob{"sha-" + name, name, "preview", "image/png", 3, json{{"preview_of", of.sha256}}};
  }
};

}  // namespace

TEST(KeepLedger, HandsOverWhatWasKeptInOrderAndForgetsIt) {
  NamingKeeper keeper;
  KeepLedger ledger;
  ledger.set_keeper(&keeper);
  const std::vector<std::uint8_t> bytes(12, 1);
  auto average = ledger.keep_bytes("average", "average", "application/x-colorlab-array", json{{"frames", 4}}, bytes);
  ledger.keep_file("raw/IMG_0001.CR2", "raw", "image/x-canon-cr2", json::object(), "/nonexistent/IMG_0001.CR2");
  ledger.keep_preview("average.png", average);

  auto kept = ledger.take();
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept[0].sha256, "sha-average");
  EXPECT_EQ(kept[0].size, 12u);
  EXPECT_EQ(kept[0].meta, (json{{"frames", 4}}));
  EXPECT_EQ(kept[1].kind, "raw");
  EXPECT_EQ(kept[2].meta, (json{{"preview_of", "sha-average"}}));
  EXPECT_TRUE(ledger.take().empty()) << "a second take hands over nothing: each call's blobs are its own";
}

TEST(KeepLedger, TheCallsJsonCarriesTheSameReference) {
  const KeptBlob b{"abc", "average", "average", "application/x-colorlab-array", 16, json{{"dtype", "<f4"}}};
  EXPECT_EQ(blob_json(b), (json{
                              {"sha256", "abc"},
                              {"name", "average"},
                              {"kind", "average"},
                              {"media_type", "application/x-colorlab-array"},
                              {"size", 16},
                              {"meta", {{"dtype", "<f4"}}},
                          }));
}
