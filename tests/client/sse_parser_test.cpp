// The client's Server-Sent Events reader against the WHATWG "interpreting an event stream" rules: events
// end at a blank line, data lines join with LF, CR / LF / CRLF all end lines, comments and unknown fields are
// skipped, the id sticks until changed, and a stream cut anywhere gives the same events.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "colorlab/client/sse.hpp"

using colorlab::client::SseEvent;
using colorlab::client::SseParser;

namespace {

std::vector<SseEvent> parse_in_pieces(const std::string& text, std::size_t piece) {
  std::vector<SseEvent> got;
  SseParser p([&](const SseEvent& e) {
    got.push_back(e);
    return true;
  });
  for (std::size_t i = 0; i < text.size(); i += piece) p.feed(std::string_view(text).substr(i, piece));
  return got;
}

TEST(SseParser, FieldsCommentsAndLineEndsAsTheSpecSays) {
  const std::string text =
      "retry: 2000\n\n"
      ": keep-alive\n\n"
      "id: 7\nevent: progress\ndata: {\"a\":1}\n\n"
      "data:first\r\ndata: second\r\n\r\n"    // CRLF; no space after the colon; the id stays 7
      "id: 9\revent: execution\rdata: x\r\r"  // lone CRs
      "event: nothing\n\n"                    // no data: not dispatched
      "id: 10\nunknown: field\ndata\n\n";     // a field without a colon: data, empty
  for (std::size_t piece : {std::size_t{1}, std::size_t{2}, std::size_t{5}, text.size()}) {
    auto got = parse_in_pieces(text, piece);
    ASSERT_EQ(got.size(), 4u) << "piece " << piece;
    EXPECT_EQ(got[0].id, "7");
    EXPECT_EQ(got[0].event, "progress");
    EXPECT_EQ(got[0].data, "{\"a\":1}");
    EXPECT_EQ(got[1].id, "7");
    EXPECT_EQ(got[1].event, "message");
    EXPECT_EQ(got[1].data, "first\nsecond");
    EXPECT_EQ(got[2].id, "9");
    EXPECT_EQ(got[2].event, "execution");
    EXPECT_EQ(got[2].data, "x");
    EXPECT_EQ(got[3].id, "10");
    EXPECT_EQ(got[3].data, "");
  }
}

TEST(SseParser, StopsWhenTheHandlerSaysSo) {
  int seen = 0;
  SseParser p([&](const SseEvent&) { return ++seen < 2; });
  EXPECT_TRUE(p.feed("data: 1\n\n"));
  EXPECT_FALSE(p.feed("data: 2\n\ndata: 3\n\n"));
  EXPECT_EQ(seen, 2);
}

TEST(SseParser, AnEventCutBeforeItsBlankLineIsNotDispatched) {
  auto got = parse_in_pieces("data: whole\n\ndata: cut off", 3);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].data, "whole");
}

}  // namespace
