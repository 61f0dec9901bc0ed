#pragma once

#include <algorithm>
#include <numeric>
#include <vector>

namespace curvesfm {

/// Disjoint sets of the nodes 0..n-1 with path halving. The root of a set is its smallest node,
/// so the sets' roots do not depend on the order of the unions (feature tracks and solver
/// components come out in the same order whatever order their links were found in).
class UnionFind {
 public:
  explicit UnionFind(int n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int find(int x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void join(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<int> parent_;
};

}  // namespace curvesfm
