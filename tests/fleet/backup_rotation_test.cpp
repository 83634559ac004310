// The backup rotation policy (docs/fleet.md, "Backups"): which snapshots stay, by their names (UTC times).
#include <gtest/gtest.h>

#include "colorlab/core/error.hpp"
#include "colorlab/fleet/backup.hpp"

using colorlab::fleet::snapshots_to_keep;
using V = std::vector<std::string>;

TEST(BackupRotation, KeepsTheNewestOfEachOfTheLastDaysAndWeeks) {
  // 2026-11-02 and 2026-11-09 are Mondays; 2026-11-01 a Sunday.
  const V names{"2026-11-01T020000.000Z", "2026-11-02T020000.000Z", "2026-11-05T020000.000Z",
                "2026-11-08T020000.000Z", "2026-11-09T020000.000Z", "2026-11-09T140000.000Z",
                "2026-11-10T020000.000Z"};
  // Two days: 11-10 and 11-09's later one. Two weeks: the newest of the week from 11-09 (11-10, kept already)
  // and of the week from 11-02 (11-08, a Sunday).
  EXPECT_EQ(snapshots_to_keep(names, 2, 2),
            (V{"2026-11-10T020000.000Z", "2026-11-09T140000.000Z", "2026-11-08T020000.000Z"}));
  // Three weeks reach the week of 2026-10-26, which holds 11-01.
  EXPECT_EQ(snapshots_to_keep(names, 0, 3), (V{"2026-11-10T020000.000Z", "2026-11-08T020000.000Z", "2026-11-01T020000.000Z"}));
}

TEST(BackupRotation, TheNewestIsAlwaysKeptAndDuplicatesCountOnce) {
  EXPECT_EQ(snapshots_to_keep({"2026-01-01T000000.000Z", "2026-03-01T000000.000Z"}, 0, 0), V{"2026-03-01T000000.000Z"});
  EXPECT_EQ(snapshots_to_keep({"2026-03-01T000000.000Z", "2026-03-01T000000.000Z"}, 5, 5), V{"2026-03-01T000000.000Z"});
  EXPECT_TRUE(snapshots_to_keep({}, 7, 4).empty());
}

TEST(BackupRotation, ANameThatIsNoTimeIsRefused) {
  EXPECT_THROW(snapshots_to_keep({"latest"}, 7, 4), colorlab::Error);
}

TEST(BackupRotation, EpochsSplitEventPositions) {
  EXPECT_EQ(colorlab::fleet::epoch_of(1), 0);
  EXPECT_EQ(colorlab::fleet::epoch_of((std::int64_t{1} << colorlab::fleet::kEpochShift) + 1), 1);
}
