#include "core/union_find.h"

#include <gtest/gtest.h>

namespace curvesfm {
namespace {

TEST(UnionFind, JoinsTransitivelyAndKeepsTheSmallestNodeAsRoot) {
  UnionFind sets(6);
  sets.join(4, 2);
  sets.join(5, 4);
  sets.join(1, 3);
  EXPECT_EQ(sets.find(5), 2);
  EXPECT_EQ(sets.find(4), 2);
  EXPECT_EQ(sets.find(3), 1);
  EXPECT_EQ(sets.find(0), 0);
  sets.join(3, 5);  // Joins {1, 3} and {2, 4, 5}.
  for (int node : {1, 2, 3, 4, 5}) EXPECT_EQ(sets.find(node), 1);
  EXPECT_EQ(sets.find(0), 0);
}

TEST(UnionFind, TheRootsDoNotDependOnTheOrderOfTheJoins) {
  UnionFind forward(5);
  UnionFind backward(5);
  forward.join(0, 3);
  forward.join(3, 4);
  backward.join(4, 3);
  backward.join(3, 0);
  for (int node = 0; node < 5; ++node) EXPECT_EQ(forward.find(node), backward.find(node));
}

}  // namespace
}  // namespace curvesfm
