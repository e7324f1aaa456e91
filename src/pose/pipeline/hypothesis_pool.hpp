#pragma once
// The best few distinct hypotheses of a search, for the refinement stage.

#include <algorithm>
#include <atomic>
#include <limits>
#include <vector>

#include "ellreloc/core/pose.hpp"

namespace ellreloc::pipeline {

/// Two poses count as one hypothesis: centres within 5 cm, rotations within 3 degrees
/// (`unit_metres`: metres per unit of the map, ObjectMap::unit_metres).
inline bool sameNeighbourhood(const Pose& a, const Pose& b, double unit_metres) {
  return (a.center() - b.center()).norm() < 0.05 / unit_metres && rotationErrorDeg(a.rotation(), b.rotation()) < 3.0;
}

/// Keeps the `capacity` lowest-cost poses, at most one per neighbourhood (sameNeighbourhood):
/// the best raw hypothesis is often not the one that refines best, and near-duplicates of it
/// would crowd out the alternatives.
class HypothesisPool {
 public:
  /// `unit_metres`: metres per unit of the map (ObjectMap::unit_metres).
  HypothesisPool(int capacity, double unit_metres)
      : capacity_(static_cast<size_t>(std::max(1, capacity))), unit_metres_(unit_metres) {}

  void offer(const Pose& pose, double cost) {
    if (entries_.size() == capacity_ && cost >= entries_.back().cost) return;
    for (ScoredPose& h : entries_) {
      if (sameNeighbourhood(h.pose, pose, unit_metres_)) {
        if (cost < h.cost) h = {pose, cost};
        sortByCost();
        return;
      }
    }
    entries_.push_back({pose, cost});
    sortByCost();
    if (entries_.size() > capacity_) entries_.pop_back();
  }

  /// The cost a pose must stay below to change the pool (infinite until it is full). Read by
  /// scorers on other threads: it only decreases, so a stale value is a safe one.
  double admissionCost() const { return admission_.load(std::memory_order_relaxed); }

  bool empty() const { return entries_.empty(); }
  const ScoredPose& best() const { return entries_.front(); }
  /// Ascending cost.
  const std::vector<ScoredPose>& entries() const { return entries_; }

 private:
  void sortByCost() {
    std::sort(entries_.begin(), entries_.end(),
              [](const ScoredPose& x, const ScoredPose& y) { return x.cost < y.cost; });
    if (entries_.size() >= capacity_) admission_.store(entries_[capacity_ - 1].cost, std::memory_order_relaxed);
  }
  size_t capacity_;
  double unit_metres_;
  std::vector<ScoredPose> entries_;
  std::atomic<double> admission_{std::numeric_limits<double>::infinity()};
};

}  // namespace ellreloc::pipeline
