// The project's one CSV reader and its writer: RFC 4180 quoting, line numbers in every error, the
// headerless grid, and a writer whose every row the reader gives back exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "colorlab/analysis/csv.hpp"
#include "colorlab/core/error.hpp"

namespace ca = colorlab::analysis;

namespace {

void expect_bad(const std::string& text, const std::string& needle, const ca::CsvOptions& o = {}) {
  try {
    ca::parse_csv(text, "bad.csv", o);
    FAIL() << "no error for: " << needle;
  } catch (const colorlab::Error& e) {
    EXPECT_EQ(e.cls(), colorlab::ErrorClass::bad_data);
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(AnalysisCsvReader, QuotedCellsMayHoldCommasQuotesAndLineBreaks) {
  auto t = ca::parse_csv("id,note,value\r\n"
                         "A1,\"a, b\",1\r\n"
                         "# a comment between rows\n"
                         "\n"
                         "\"A2\",\"say \"\"hi\"\"\",2\n"
                         "A3,\"two\nlines\",3",
                         "m.csv");
  ASSERT_EQ(t.header, (std::vector<std::string>{"id", "note", "value"}));
  ASSERT_EQ(t.rows.size(), 3u);
  EXPECT_EQ(t.rows[0][1], "a, b");
  EXPECT_EQ(t.rows[1][0], "A2");
  EXPECT_EQ(t.rows[1][1], "say \"hi\"");
  EXPECT_EQ(t.rows[2][1], "two\nlines");
  EXPECT_EQ(t.row_lines, (std::vector<std::size_t>{2, 5, 6}));
  EXPECT_DOUBLE_EQ(t.number(2, 2), 3);
}

TEST(AnalysisCsvReader, ErrorsNameTheFileAndLine) {
  expect_bad("a,b\n1,2\n\n1,2,3\n", "bad.csv:4: 3 cells, header has 2");
  expect_bad("a,b\n1,\"open\n2,3\n", "bad.csv:2: quoted cell is never closed");
  expect_bad("a,b\n\"x\"y,1\n", "bad.csv:2: text after the closing quote");
  expect_bad("# only a comment\n", "no header row");
  // A number error names the row's own line, past comments and a quoted line break.
  auto t = ca::parse_csv("a,b\n# c\n\"x\ny\",oops\n", "m.csv");
  try {
    (void)t.number(0, 1);
    FAIL();
  } catch (const colorlab::Error& e) {
    EXPECT_NE(std::string(e.what()).find("m.csv:3, column 'b': 'oops' is not a number"), std::string::npos) << e.what();
  }
}

TEST(AnalysisCsvReader, HeaderlessGridsAndSingleRows) {
  auto g = ca::parse_csv("1,2,3,\n4,5,6\n", "g.csv", {.header = false});
  EXPECT_TRUE(g.header.empty());
  ASSERT_EQ(g.columns(), 3u);
  ASSERT_EQ(g.rows.size(), 2u);
  EXPECT_DOUBLE_EQ(g.number(1, 2), 6);
  EXPECT_FALSE(g.try_number(0, 5).has_value());
  expect_bad("1,2\n3\n", "bad.csv:2: 1 cells, first row has 2", {.header = false});
  EXPECT_EQ(ca::parse_csv_row("10, 20,\"a,b\"", "--opt"), (std::vector<std::string>{"10", " 20", "a,b"}));
  EXPECT_THROW(ca::parse_csv_row("1\n2", "--opt"), colorlab::Error);
}

TEST(AnalysisCsvWriter, EveryRowReadsBackExactly) {
  std::mt19937_64 rng(11);
  const std::string alphabet = "ab ,\"\n\r#x;1.-";
  std::uniform_int_distribution<std::size_t> pick(0, alphabet.size() - 1), len(0, 6);
  std::vector<std::vector<std::string>> rows;
  std::string text;
  ca::append_csv_row(text, {"text", "number", "other"});
  std::uniform_real_distribution<double> mant(-1, 1);
  std::uniform_int_distribution<int> exp10(-300, 300);
  for (int r = 0; r < 400; ++r) {
    std::string s;
    for (std::size_t k = len(rng); k > 0; --k) s += alphabet[pick(rng)];
    const double v = mant(rng) * std::pow(10.0, exp10(rng));
    std::vector<std::string> row{s, ca::csv_number(v), r % 7 == 0 ? "" : "#" + s};
    ca::append_csv_row(text, row);
    rows.push_back(row);
    // The number's text gives back the very double.
    EXPECT_EQ(std::stod(row[1]), v);
  }
  const auto t = ca::parse_csv(text, "w.csv");
  ASSERT_EQ(t.rows.size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(t.rows[i], rows[i]) << "row " << i;
  // A row of one empty cell is not a blank line.
  std::string one;
  ca::append_csv_row(one, {"only"});
  ca::append_csv_row(one, {""});
  EXPECT_EQ(ca::parse_csv(one, "one.csv").rows, (std::vector<std::vector<std::string>>{{""}}));
  EXPECT_EQ(ca::csv_number(0.1), "0.1");
  EXPECT_EQ(ca::csv_number(std::numeric_limits<double>::max()), "1.7976931348623157e+308");
}

}  // namespace
