#include "candidates.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace ellreloc::pipeline {

namespace {

/// The label share through which a usable map object m may be observation o, or a negative
/// number when it may not (another category, or below the options' share).
double candidateShare(const Observation& o, const MapObject& m, const ScoringOptions& options) {
  const double share =
      m.category == o.category ? std::max(m.categoryShare(o.category), 0.5) : m.categoryShare(o.category);
  if (!(share >= std::min(options.min_category_share, 0.5) &&
        (m.category == o.category || share >= options.min_category_share)))
    return -1.0;
  return share;
}

/// A strict weak order on doubles for sorting: numbers ascending, then NaN.
bool lessNanLast(double a, double b) { return !std::isnan(a) && (std::isnan(b) || a < b); }

/// Every field of an observation, as the canonical order compares them.
using SortKey = std::array<double, 14>;
SortKey sortKey(const Observation& o) {
  const Box& b = o.box;
  const Ellipse& e = o.ellipse;
  return {-o.score,
          static_cast<double>(o.category),
          b.x1,
          b.y1,
          b.x2,
          b.y2,
          e.center()(0),
          e.center()(1),
          e.axes()(0),
          e.axes()(1),
          e.angle(),
          static_cast<double>(o.source),
          o.regular ? static_cast<double>(*o.regular) : -1.0,
          static_cast<double>(o.truncated)};
}

}  // namespace

std::vector<int> canonicalOrder(const std::vector<Observation>& observations) {
  std::vector<SortKey> keys;
  keys.reserve(observations.size());
  for (const Observation& o : observations) keys.push_back(sortKey(o));
  std::vector<int> order(observations.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    const SortKey &ka = keys[static_cast<size_t>(a)], &kb = keys[static_cast<size_t>(b)];
    return std::lexicographical_compare(ka.begin(), ka.end(), kb.begin(), kb.end(), lessNanLast);
  });
  return order;
}

double usableTriplets(const Candidates& candidates) {
  // The third elementary symmetric sum of the candidate counts, built one observation at a time.
  double singles = 0.0, twos = 0.0, threes = 0.0;
  for (const std::vector<int>& objects : candidates.of_observation) {
    const double count = static_cast<double>(objects.size());
    threes += twos * count;
    twos += singles * count;
    singles += count;
  }
  return threes;
}

Candidates collectCandidates(const std::vector<Observation>& observations, const ObjectMap& map,
                             const ScoringOptions& options, long max_pairs,
                             std::vector<std::pair<int, std::string>>* skipped) {
  Candidates c;
  c.usable.assign(observations.size(), 0);
  c.of_observation.resize(observations.size());
  // Candidate counts first, so that no pair beyond max_pairs is ever stored: when the frame
  // and map would give more, the most confident observations (detection score, then order)
  // keep their candidates.
  std::vector<long> count(observations.size(), 0);
  std::vector<size_t> order;
  std::vector<char> object_usable(map.objects.size());  // checked once per object, not per pair
  for (size_t j = 0; j < map.objects.size(); ++j) object_usable[j] = mapObjectUsable(map.objects[j], map.unit_metres);
  for (size_t i = 0; i < observations.size(); ++i) {
    const Observation& o = observations[i];
    if (!o.ellipse.isValid() || !o.box.isValid() || !std::isfinite(o.score)) {
      skipped->emplace_back(static_cast<int>(i), "invalid ellipse, box or score (NaN, infinite or empty)");
      continue;
    }
    for (size_t j = 0; j < map.objects.size(); ++j)
      count[i] += object_usable[j] && candidateShare(o, map.objects[j], options) >= 0.0;
    if (count[i] == 0) {
      skipped->emplace_back(static_cast<int>(i), "no map object of category " + std::to_string(o.category));
      continue;
    }
    order.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return observations[a].score > observations[b].score; });
  long total = 0;
  for (size_t i : order) {
    if (total + count[i] > max_pairs) {
      skipped->emplace_back(static_cast<int>(i), "beyond the bound of " + std::to_string(max_pairs) +
                                                     " candidate pairs (search.max_candidate_pairs)");
      continue;
    }
    total += count[i];
    c.usable[i] = 1;
    ++c.num_usable;
  }
  c.pairs.reserve(static_cast<size_t>(total));
  for (size_t i = 0; i < observations.size(); ++i) {
    if (!c.usable[i]) continue;
    const Observation& o = observations[i];
    for (size_t j = 0; j < map.objects.size(); ++j) {
      const MapObject& m = map.objects[j];
      const double share = object_usable[j] ? candidateShare(o, m, options) : -1.0;
      if (share < 0.0) continue;
      c.of_observation[i].push_back(static_cast<int>(j));
      // Likelier labels, surer detections and larger objects first: PROSAC order.
      c.pairs.push_back({static_cast<int>(i), static_cast<int>(j), share * o.score * std::cbrt(m.ellipsoid.volume())});
    }
  }
  std::sort(skipped->begin(), skipped->end());
  std::stable_sort(c.pairs.begin(), c.pairs.end(),
                   [](const CandidatePair& a, const CandidatePair& b) { return a.quality > b.quality; });
  return c;
}

Candidates candidatesWithinRegion(const Candidates& candidates, const std::vector<Observation>& observations,
                                  const ObjectMap& map, const Intrinsics& K, const PoseRegion& region) {
  if (region.max_rotation_deg >= 180.0) return candidates;
  const double turn = region.max_rotation_deg * M_PI / 180.0;
  const Eigen::Vector3d centre = region.pose.center();
  const Eigen::Matrix3d& R = region.pose.rotation();
  Candidates c;
  c.usable = candidates.usable;
  c.num_usable = candidates.num_usable;
  c.of_observation.resize(candidates.of_observation.size());
  // Each pair's verdict once, by observation and object: `pairs` holds the same pairs in PROSAC order.
  std::vector<std::vector<char>> reachable(candidates.of_observation.size());
  for (size_t i = 0; i < candidates.of_observation.size(); ++i) {
    if (candidates.of_observation[i].empty()) continue;
    reachable[i].assign(map.objects.size(), 0);
    const Eigen::Vector3d bearing = K.bearing(observations[i].ellipse.center());
    for (const int j : candidates.of_observation[i]) {
      const Eigen::Vector3d to_object = map.objects[static_cast<size_t>(j)].ellipsoid.center() - centre;
      const double distance = to_object.norm();
      // The camera may be next to the object: any direction. A pair on the bound is kept: the
      // gate, not this, decides poses there.
      bool keep = !(distance > region.radius_m);
      if (!keep) {
        const Eigen::Vector3d seen = R * to_object;
        const double off = std::atan2(seen.cross(bearing).norm(), seen.dot(bearing));
        keep = off <= turn + std::asin(region.radius_m / distance) + 1e-9;
      }
      if (keep) c.of_observation[i].push_back(j);
      reachable[i][static_cast<size_t>(j)] = keep;
    }
  }
  for (const CandidatePair& p : candidates.pairs)
    if (reachable[static_cast<size_t>(p.observation)][static_cast<size_t>(p.object)]) c.pairs.push_back(p);
  return c;
}

}  // namespace ellreloc::pipeline
