// The drift yardstick (LightReference): what a reading is held to, when it is a drift, and how a light that
// settled at a new level becomes the reference.
#include <gtest/gtest.h>

#include "colorlab/campaigns/light_reference.hpp"

using colorlab::campaigns::LightReference;

namespace {

const std::vector<std::string> kD65{"D65"};

TEST(LightReference, NothingToCompareWithUntilTheLampsWereFoundStable) {
  LightReference ref(3);
  EXPECT_FALSE(ref.check(kD65, 100, 300));
  EXPECT_FALSE(ref.check(kD65, 100, 100));  // and the unchecked reading taught it nothing
  ref.stable(kD65, 100, 300);
  EXPECT_FALSE(ref.check(kD65, 100, 308.9));  // +2.97 %: within the tolerance
  EXPECT_FALSE(ref.check(kD65, 100, 291.1));
  auto drift = ref.check(kD65, 100, 309.3);  // +3.1 %
  ASSERT_TRUE(drift);
  EXPECT_NEAR(drift->change_pct, 3.1, 1e-9);
  EXPECT_DOUBLE_EQ(drift->expected, 300);
  EXPECT_EQ(drift->lamps, kD65);
  EXPECT_DOUBLE_EQ(drift->dimmer_percent, 100);
  // A drifted reading does not become the reference: the next one is held to the same 300.
  EXPECT_TRUE(ref.check(kD65, 100, 280));
  EXPECT_DOUBLE_EQ(*ref.expected(kD65, 100), 300);
}

TEST(LightReference, EachDimmerLevelIsHeldToItsOwnFirstReading) {
  // A real dimmer is not proportional (the simulated one gives 44 % of the light at 50 %), so a level's
  // reference is its first reading since the lamps were found stable, never a scaled 100 % reading.
  LightReference ref(3);
  ref.stable(kD65, 100, 300);
  EXPECT_FALSE(ref.check(kD65, 50, 133));
  EXPECT_FALSE(ref.check(kD65, 50, 134));
  EXPECT_TRUE(ref.check(kD65, 50, 125));
  EXPECT_FALSE(ref.check(kD65, 100, 301));
}

TEST(LightReference, OtherLampsOrAForgottenReferenceAreNotCompared) {
  LightReference ref(3);
  ref.stable(kD65, 100, 300);
  EXPECT_FALSE(ref.check({"TL84"}, 100, 100));
  EXPECT_FALSE(ref.check({"D65", "TL84"}, 100, 600));
  ref.moved();  // the meter was aimed elsewhere: each level's first reading there is its reference
  EXPECT_FALSE(ref.check(kD65, 100, 200));
  EXPECT_DOUBLE_EQ(*ref.expected(kD65, 100), 200);
  EXPECT_TRUE(ref.check(kD65, 100, 210));
  ref.forget();  // the lamps changed: nothing until they are found stable again
  EXPECT_FALSE(ref.check(kD65, 100, 300));
  EXPECT_FALSE(ref.expected(kD65, 100));
  // No lamp lit, or no light: no yardstick (relative changes of darkness are noise).
  ref.stable({}, 100, 0.002);
  EXPECT_FALSE(ref.check({}, 100, 0.004));
  ref.stable(kD65, 100, 0);
  EXPECT_FALSE(ref.check(kD65, 100, 1));
}

TEST(LightReference, ALightThatSettledAtANewLevelIsTheReferenceFromThenOn) {
  LightReference ref(3);
  ref.stable(kD65, 100, 300);
  EXPECT_FALSE(ref.check(kD65, 50, 133));
  EXPECT_TRUE(ref.check(kD65, 50, 120));  // the lamp drifted down by about 10 %
  auto change = ref.settle_at(kD65, 50, 119.7);
  ASSERT_TRUE(change);
  EXPECT_NEAR(*change, -10, 1e-9);
  EXPECT_DOUBLE_EQ(*ref.expected(kD65, 50), 119.7);
  EXPECT_FALSE(ref.check(kD65, 50, 120.5));
  // The 100 % reference was taken before the drift was noticed (it may itself have drifted): learned again.
  EXPECT_FALSE(ref.expected(kD65, 100));
  EXPECT_FALSE(ref.check(kD65, 100, 280));
  EXPECT_TRUE(ref.check(kD65, 100, 260));
  // Settling where there was no reference starts one.
  ref.forget();
  EXPECT_FALSE(ref.settle_at(kD65, 25, 60));
  EXPECT_DOUBLE_EQ(*ref.expected(kD65, 25), 60);
}

}  // namespace
