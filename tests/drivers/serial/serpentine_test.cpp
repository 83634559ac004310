// Serpentine visiting order (Argyll ss.c): rows run along whichever of step and pass moves further
// in X and alternate direction; every patch is visited exactly once.
#include <gtest/gtest.h>

#include "colorlab/core/error.hpp"
#include "colorlab/drivers/serpentine.hpp"

namespace colorlab::test {
namespace {

using drivers::ChartLayout;

std::vector<std::vector<int>> indices(const ChartLayout& l) {
  std::vector<std::vector<int>> out;
  for (const auto& row : drivers::serpentine_rows(l)) {
    out.emplace_back();
    for (const auto& p : row) out.back().push_back(p.index);
  }
  return out;
}

TEST(Serpentine, StripsDownTheTableAreReadAcrossInAlternatingRows) {
  // 3 strips (columns, 20 mm apart in X) of 4 patches (10 mm apart in Y): rows run along X.
  ChartLayout l{10, 10, 0, 10, 20, 0, 4, 3, 0};
  EXPECT_EQ(indices(l), (std::vector<std::vector<int>>{{0, 4, 8}, {9, 5, 1}, {2, 6, 10}, {11, 7, 3}}));
  auto rows = drivers::serpentine_rows(l);
  EXPECT_DOUBLE_EQ(rows[1][0].x_mm, 50);  // strip 2
  EXPECT_DOUBLE_EQ(rows[1][0].y_mm, 20);  // patch 1
}

TEST(Serpentine, StripsAcrossTheTableAreReadAlongEachStrip) {
  ChartLayout l{10, 10, 15, 0, 0, 12, 3, 2, 0};
  EXPECT_EQ(indices(l), (std::vector<std::vector<int>>{{0, 1, 2}, {5, 4, 3}}));
}

TEST(Serpentine, ShortLastStripAndBadLayouts) {
  ChartLayout l{10, 10, 15, 0, 0, 12, 3, 2, 5};
  EXPECT_EQ(indices(l), (std::vector<std::vector<int>>{{0, 1, 2}, {4, 3}}));
  EXPECT_THROW(drivers::serpentine_rows(ChartLayout{10, 10, 15, 0, 0, 12, 0, 2, 0}), Error);
  EXPECT_THROW(drivers::serpentine_rows(ChartLayout{10, 10, 15, 0, 0, 12, 3, 2, 7}), Error);
  EXPECT_THROW(drivers::serpentine_rows(ChartLayout{300, 10, 15, 0, 0, 12, 3, 2, 0}), Error);  // off the table
}

}  // namespace
}  // namespace colorlab::test
