#pragma once
// The best few distinct hypotheses of a search, for the refinement stage.

#include <algorithm>
#include <vector>

#include "ellreloc/core/pose.hpp"

namespace ellreloc::pipeline {

/// Keeps the `capacity` lowest-cost poses, at most one per neighbourhood (5 cm, 3 degrees):
/// the best raw hypothesis is often not the one that refines best, and near-duplicates of it
/// would crowd out the alternatives.
class HypothesisPool {
 public:
  explicit HypothesisPool(int capacity) : capacity_(static_cast<size_t>(std::max(1, capacity))) {}

  void offer(const Pose& pose, double cost) {
    if (entries_.size() == capacity_ && cost >= entries_.back().cost) return;
    for (ScoredPose& h : entries_) {
      if ((h.pose.center() - pose.center()).norm() < 0.05 &&
          rotationErrorDeg(h.pose.rotation(), pose.rotation()) < 3.0) {
        if (cost < h.cost) h = {pose, cost};
        sortByCost();
        return;
      }
    }
    entries_.push_back({pose, cost});
    sortByCost();
    if (entries_.size() > capacity_) entries_.pop_back();
  }

  bool empty() const { return entries_.empty(); }
  const ScoredPose& best() const { return entries_.front(); }
  /// Ascending cost.
  const std::vector<ScoredPose>& entries() const { return entries_; }

 private:
  void sortByCost() {
    std::sort(entries_.begin(), entries_.end(),
              [](const ScoredPose& x, const ScoredPose& y) { return x.cost < y.cost; });
  }
  size_t capacity_;
  std::vector<ScoredPose> entries_;
};

}  // namespace ellreloc::pipeline
