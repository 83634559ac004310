#include <gtest/gtest.h>

#include "colorlab/http/message.hpp"

using colorlab::http::HttpRequest;

TEST(HttpTarget, SplitsPathAndDecodesQuery) {
  HttpRequest r;
  r.target = "/v1/runs?limit=5&cursor=12&name=a%20b+c";
  ASSERT_TRUE(r.parse_target());
  EXPECT_EQ(r.path, "/v1/runs");
  EXPECT_EQ(r.query["limit"], "5");
  EXPECT_EQ(r.query["cursor"], "12");
  EXPECT_EQ(r.query["name"], "a b c");
}

TEST(HttpTarget, RejectsMalformedTargets) {
  for (const char* t : {"", "v1/runs", "/v1/%zz", "/v1?x=%4"}) {
    HttpRequest r;
    r.target = t;
    EXPECT_FALSE(r.parse_target()) << t;
  }
}
