#include <gtest/gtest.h>

#include <set>
#include <string>

#include "ellreloc/core/coco.hpp"

using namespace ellreloc;

// The ids the shared data's README lists for its labelme instances, and the table's ends.
TEST(Coco, NamesFollowTheZeroBasedCoco80Ids) {
  EXPECT_STREQ(cocoCategoryName(0), "person");
  EXPECT_STREQ(cocoCategoryName(2), "car");
  EXPECT_STREQ(cocoCategoryName(5), "bus");
  EXPECT_STREQ(cocoCategoryName(39), "bottle");
  EXPECT_STREQ(cocoCategoryName(56), "chair");
  EXPECT_STREQ(cocoCategoryName(57), "couch");
  EXPECT_STREQ(cocoCategoryName(62), "tv");
  EXPECT_STREQ(cocoCategoryName(73), "book");
  EXPECT_STREQ(cocoCategoryName(79), "toothbrush");
  EXPECT_EQ(cocoCategoryName(80), nullptr);
  EXPECT_EQ(cocoCategoryName(-1), nullptr);
  std::set<std::string> names;
  for (int id = 0; id < 80; ++id) names.insert(cocoCategoryName(id));
  EXPECT_EQ(names.size(), 80u);
}
