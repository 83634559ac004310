// central's answer tags (central_cache.hpp): the quoted SHA-256 of the body's bytes. The expected digests are the
// FIPS 180-2 examples (the empty message and "abc"), not this code's output.
#include <gtest/gtest.h>

#include <string>

#include "colorlab/fleet/central_cache.hpp"

namespace colorlab::fleet {
namespace {

TEST(CentralCache, ABodysTagIsTheQuotedSha256OfItsBytes) {
  EXPECT_EQ(body_etag(""), "\"e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855\"");
  EXPECT_EQ(body_etag("abc"), "\"ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad\"");
}

TEST(CentralCache, AKeptAnswerCarriesItsBodysTagAndOneChangedByteChangesIt) {
  AnswerCache cache(1 << 20);
  const std::string body = R"({"items":[{"seq":1}]})";
  const auto kept = cache.keep("/v1/runs", "v1", body);
  EXPECT_EQ(kept.etag, body_etag(body));
  const auto found = cache.find("/v1/runs", "v1");
  ASSERT_TRUE(found);
  EXPECT_EQ(found->etag, kept.etag);
  EXPECT_NE(body_etag(R"({"items":[{"seq":2}]})"), kept.etag);
}

}  // namespace
}  // namespace colorlab::fleet
