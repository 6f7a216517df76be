#include "skeleton/joints.h"

#include <gtest/gtest.h>

namespace drape {

TEST(Joints, HierarchyIsTopDown) {
  EXPECT_EQ(kJointParent[0], -1);
  for (int j = 1; j < kJointCount; ++j) {
    EXPECT_GE(kJointParent[j], 0) << jointName(static_cast<Joint>(j));
    EXPECT_LT(kJointParent[j], j) << "parent must come first: " << jointName(static_cast<Joint>(j));
  }
}

TEST(Joints, LayoutJointCounts) {
  EXPECT_EQ(layoutJointCount(Layout::Kinect1), 20);
  EXPECT_EQ(layoutJointCount(Layout::Kinect2), 25);
  EXPECT_EQ(layoutJointCount(Layout::Azure), 32);
  EXPECT_EQ(layoutJointCount(static_cast<Layout>(7)), 0);
  EXPECT_FALSE(isValidLayout(0));
  EXPECT_FALSE(isValidLayout(4));
  EXPECT_TRUE(isValidLayout(2));
}

}  // namespace drape
