#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "ellreloc/mapping/association.hpp"
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

// 2D association (the paper's tracking cost): the pairs of highest IoU, a label mismatch only at
// IoU >= 0.5, nothing below 0.2.
TEST(AssociateBoxes, FollowsOverlapAndLabels) {
  const int kCup = 41, kBook = 73;
  const std::vector<LabelledBox> objects{
      {Box(0, 0, 100, 100), kCup}, {Box(200, 0, 300, 100), kCup}, {Box(400, 0, 500, 100), kBook}};
  const std::vector<LabelledBox> detections{
      {Box(205, 5, 305, 105), kCup},  // object 1 (IoU 0.82)
      {Box(10, 10, 110, 110), kCup},  // object 0 (IoU 0.68)
      {Box(430, 0, 530, 100), kCup},  // the book's box at IoU 0.54: another label, overlapping enough
      {Box(600, 0, 700, 100), kCup},  // nothing there
  };
  EXPECT_EQ(associateBoxes(objects, detections), std::vector<int>({1, 0, 2, -1}));
  std::vector<LabelledBox> weak = detections;
  weak[2].box = Box(450, 0, 550, 100);  // IoU 0.33 with the book: too little for another label
  EXPECT_EQ(associateBoxes(objects, weak), std::vector<int>({1, 0, -1, -1}));
}

// A pair the gate rules out is never kept; the assignment then gives the detection to the
// object it may join, if their boxes overlap enough.
TEST(AssociateBoxes, AGateRulesPairsOut) {
  const int kBottle = 39;
  const std::vector<LabelledBox> objects{{Box(100, 100, 140, 200), kBottle}, {Box(110, 100, 150, 200), kBottle}};
  const std::vector<LabelledBox> detections{{Box(100, 100, 140, 200), kBottle}};  // object 0's box exactly
  EXPECT_EQ(associateBoxes(objects, detections), std::vector<int>({0}));
  PairGate gate = PairGate::Constant(2, 1, true);
  gate(0, 0) = false;                                                               // e.g. a metre apart in depth
  EXPECT_EQ(associateBoxes(objects, detections, {}, gate), std::vector<int>({1}));  // IoU 0.6
  gate(1, 0) = false;
  EXPECT_EQ(associateBoxes(objects, detections, {}, gate), std::vector<int>({-1}));
}

}  // namespace
}  // namespace ellreloc
