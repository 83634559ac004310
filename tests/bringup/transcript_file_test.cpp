// The transcript file format (docs/bring-up.md, "Transcript files"): a round trip, refusals with the
// file and line, and how expected values are compared.
#include <fstream>

#include <gtest/gtest.h>

#include "colorlab/bringup/transcript_file.hpp"
#include "colorlab/core/error.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace colorlab::test {
namespace {

namespace bu = colorlab::bringup;
using nlohmann::json;
using namespace std::string_literals;

TEST(TranscriptFile, RoundTripKeepsEveryByteAndTheExpectedValues) {
  testing::TempDir dir;
  bu::TranscriptFile f;
  f.header = {{"port", "/dev/ttyUSB0"}, {"plan", {{"expect", "ls110"}, {"measure", true}}}};
  f.events = {{bu::ByteEvent::Kind::settings, 0.0, "4800 7E2 none"},
              {bu::ByteEvent::Kind::host, 0.5, "MES\r\n"},
              {bu::ByteEvent::Kind::device, 512.25, "OK00,\x00\xff 1\r\n"s}};
  f.expected = {{"luminance", {{"value", 1.0}, {"tolerance", 0.05}}}};
  f.expected_source = "operator";
  bu::write_transcript(dir / "t.jsonl", f);
  auto g = bu::read_transcript(dir / "t.jsonl");
  EXPECT_EQ(g.header["colorlab_transcript"], 1);
  ASSERT_EQ(g.events.size(), 3u);
  EXPECT_EQ(g.events[2].data, "OK00,\x00\xff 1\r\n"s);
  EXPECT_EQ(g.events[2].kind, bu::ByteEvent::Kind::device);
  EXPECT_DOUBLE_EQ(g.events[2].t_ms, 512.25);
  EXPECT_EQ(g.expected, f.expected);
  EXPECT_EQ(g.expected_source, "operator");
}

TEST(TranscriptFile, RefusalsNameTheFileAndLine) {
  testing::TempDir dir;
  auto write = [&](const std::string& text) {
    std::ofstream(dir / "bad.jsonl") << text;
    try {
      bu::read_transcript(dir / "bad.jsonl");
    } catch (const Error& e) {
      EXPECT_EQ(e.cls(), ErrorClass::bad_data);
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(write("{\"port\":\"x\"}\n").find("bad.jsonl:1"), std::string::npos);
  EXPECT_NE(write("{\"colorlab_transcript\":1}\n{\"host\":\"4d4\"}\n").find("bad.jsonl:2"), std::string::npos);
  EXPECT_NE(write("{\"colorlab_transcript\":1}\n{\"host\":\"zz\"}\n").find("hex"), std::string::npos);
  EXPECT_NE(write("{\"colorlab_transcript\":2}\n").find("format"), std::string::npos);
  EXPECT_NE(write("{\"colorlab_transcript\":1}\nnot json\n").find("bad.jsonl:2"), std::string::npos);
  EXPECT_NE(write("").find("empty"), std::string::npos);
}

TEST(CompareExpected, NumbersWithinTheirToleranceStringsExactlyArraysElementwise) {
  EXPECT_EQ(bu::compare_expected("l", {{"value", 245.5}, {"tolerance", 0.05}}, 245.54), "");
  EXPECT_NE(bu::compare_expected("l", {{"value", 245.5}, {"tolerance", 0.05}}, 245.56), "");
  EXPECT_NE(bu::compare_expected("l", {{"value", 245.5}}, json()), "");
  EXPECT_EQ(bu::compare_expected("s", {{"value", "12345678"}}, "12345678"), "");
  EXPECT_NE(bu::compare_expected("s", {{"value", "12345678"}}, "12345679"), "");
  EXPECT_EQ(bu::compare_expected("a", {{"value", {0.1, 0.2}}, {"tolerance", 1e-6}}, json{0.1, 0.2}), "");
  auto why = bu::compare_expected("a", {{"value", {0.1, 0.2}}, {"tolerance", 1e-6}}, json{0.1, 0.3});
  EXPECT_NE(why.find("a[1]"), std::string::npos) << why;
  EXPECT_NE(bu::compare_expected("a", {{"value", {0.1, 0.2}}}, json{0.1}), "");
}

}  // namespace
}  // namespace colorlab::test
