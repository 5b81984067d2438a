#include "dyncull/culling/motion_levels.hpp"

#include <gtest/gtest.h>

namespace {
using namespace dyncull;

TEST(MotionLevels, Coco80TableIsComplete) {
  const MotionLevelTable t = MotionLevelTable::coco80();
  ASSERT_EQ(t.size(), 80u);
  ASSERT_EQ(coco80_names().size(), 80u);
  for (int id = 0; id < 80; ++id) {
    EXPECT_NE(t.level(id), MotionLevel::Ignore) << t.name(id);
    EXPECT_FALSE(t.name(id).empty());
    EXPECT_EQ(t.id_of(t.name(id)), id);
  }
  EXPECT_EQ(t.name(56), "chair");
  EXPECT_EQ(t.name(62), "tv");
  EXPECT_EQ(t.name(79), "toothbrush");
}

TEST(MotionLevels, DefaultLevelsFollowThePapers) {
  const MotionLevelTable t = MotionLevelTable::coco80();
  for (const char* high : {"person", "cat", "dog", "horse", "bird", "bear", "car", "bicycle"})
    EXPECT_EQ(t.level(t.id_of(high)), MotionLevel::High) << high;
  for (const char* medium : {"chair", "book", "keyboard", "mouse", "cup", "bottle", "cell phone", "backpack", "handbag",
                             "laptop", "remote", "suitcase"})
    EXPECT_EQ(t.level(t.id_of(medium)), MotionLevel::Medium) << medium;
  for (const char* low : {"tv", "refrigerator", "bed", "dining table", "couch", "potted plant", "sink", "oven", "clock"})
    EXPECT_EQ(t.level(t.id_of(low)), MotionLevel::Low) << low;
}

TEST(MotionLevels, UnknownIdsAreIgnored) {
  const MotionLevelTable t = MotionLevelTable::coco80();
  EXPECT_EQ(t.level(-1), MotionLevel::Ignore);
  EXPECT_EQ(t.level(80), MotionLevel::Ignore);
  EXPECT_EQ(t.id_of("unicorn"), -1);
  EXPECT_EQ(t.name(1000), "");
}

TEST(MotionLevels, ReplaceableByIdAndByName) {
  MotionLevelTable t = MotionLevelTable::coco80();
  EXPECT_TRUE(t.set("chair", MotionLevel::Low));
  EXPECT_EQ(t.level(56), MotionLevel::Low);
  EXPECT_TRUE(t.set(2, MotionLevel::Medium));  // parked cars
  EXPECT_EQ(t.level(t.id_of("car")), MotionLevel::Medium);
  EXPECT_FALSE(t.set("unicorn", MotionLevel::High));
  EXPECT_FALSE(t.set(-3, MotionLevel::High));
  EXPECT_TRUE(t.set(90, MotionLevel::High));  // a custom detector class past COCO
  EXPECT_EQ(t.size(), 91u);
  EXPECT_EQ(t.level(90), MotionLevel::High);
  EXPECT_EQ(t.level(85), MotionLevel::Ignore);
}

TEST(MotionLevels, CustomTableAndScores) {
  MotionLevelTable t({"human", "box"}, MotionLevel::Low);
  t.set("human", MotionLevel::High);
  EXPECT_EQ(t.level(0), MotionLevel::High);
  EXPECT_EQ(t.level(1), MotionLevel::Low);
  // S of DLD-SLAM eq. 3 as Algorithm 1 defines it.
  EXPECT_EQ(motion_level_score(MotionLevel::High), 1.0);
  EXPECT_EQ(motion_level_score(MotionLevel::Medium), 0.5);
  EXPECT_EQ(motion_level_score(MotionLevel::Low), 0.0);
  EXPECT_EQ(motion_level_score<float>(MotionLevel::Ignore), 0.f);
  EXPECT_STREQ(to_string(MotionLevel::Medium), "medium");
}
}  // namespace
