#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "ellreloc/mapping/hungarian.hpp"

namespace ellreloc {
namespace {

/// The best total over every injective map from the smaller side to the larger one.
double bruteForceBest(const Eigen::MatrixXd& C) {
  const bool t = C.rows() > C.cols();
  const Eigen::MatrixXd M = t ? Eigen::MatrixXd(C.transpose()) : C;
  std::vector<int> cols(static_cast<size_t>(M.cols()));
  std::iota(cols.begin(), cols.end(), 0);
  double best = 1e300;
  do {  // every permutation; the first rows() entries give the assignment
    double s = 0;
    for (long i = 0; i < M.rows(); ++i) s += M(i, cols[static_cast<size_t>(i)]);
    best = std::min(best, s);
  } while (std::next_permutation(cols.begin(), cols.end()));
  return best;
}

double totalOf(const Eigen::MatrixXd& C, const std::vector<int>& a) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i] >= 0) s += C(static_cast<long>(i), a[i]);
  return s;
}

TEST(Hungarian, MatchesBruteForceOnRandomRectangularMatrices) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-3.0, 10.0);
  for (int trial = 0; trial < 400; ++trial) {
    const int rows = 1 + trial % 6, cols = 1 + (trial / 6) % 6;
    Eigen::MatrixXd C(rows, cols);
    for (int i = 0; i < rows; ++i)
      for (int j = 0; j < cols; ++j) C(i, j) = trial % 3 == 0 ? std::round(u(rng)) : u(rng);  // ties too
    const std::vector<int> a = hungarianAssignment(C);
    ASSERT_EQ(a.size(), static_cast<size_t>(rows));
    std::vector<int> used;
    for (int j : a)
      if (j >= 0) used.push_back(j);
    std::sort(used.begin(), used.end());
    EXPECT_EQ(std::adjacent_find(used.begin(), used.end()), used.end()) << "a column used twice";
    EXPECT_EQ(used.size(), static_cast<size_t>(std::min(rows, cols)));
    EXPECT_NEAR(totalOf(C, a), bruteForceBest(C), 1e-9) << rows << "x" << cols;
  }
}

TEST(Hungarian, EmptyAndObviousCases) {
  EXPECT_TRUE(hungarianAssignment(Eigen::MatrixXd(0, 0)).empty());
  EXPECT_EQ(hungarianAssignment(Eigen::MatrixXd(0, 3)).size(), 0u);
  EXPECT_EQ(hungarianAssignment(Eigen::MatrixXd(2, 0)), std::vector<int>({-1, -1}));
  Eigen::MatrixXd C(3, 3);
  C << 9, 1, 9, 1, 9, 9, 9, 9, 1;
  EXPECT_EQ(hungarianAssignment(C), std::vector<int>({1, 0, 2}));
}

}  // namespace
}  // namespace ellreloc
