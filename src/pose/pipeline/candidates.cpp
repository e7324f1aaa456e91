#include "candidates.hpp"

#include <algorithm>
#include <cmath>

namespace ellreloc::pipeline {

Candidates collectCandidates(const std::vector<Observation>& observations, const ObjectMap& map,
                             const ScoringOptions& options, std::vector<std::pair<int, std::string>>* skipped) {
  Candidates c;
  c.usable.assign(observations.size(), 0);
  c.of_observation.resize(observations.size());
  for (size_t i = 0; i < observations.size(); ++i) {
    const Observation& o = observations[i];
    if (!o.ellipse.isValid() || !o.box.isValid() || !std::isfinite(o.score)) {
      skipped->emplace_back(static_cast<int>(i), "invalid ellipse, box or score (NaN, infinite or empty)");
      continue;
    }
    for (size_t j = 0; j < map.objects.size(); ++j) {
      const MapObject& m = map.objects[j];
      const double share =
          m.category == o.category ? std::max(m.categoryShare(o.category), 0.5) : m.categoryShare(o.category);
      if (!mapObjectUsable(m) || !(share >= std::min(options.min_category_share, 0.5) &&
                                   (m.category == o.category || share >= options.min_category_share)))
        continue;
      c.of_observation[i].push_back(static_cast<int>(j));
      // Likelier labels, surer detections and larger objects first: PROSAC order.
      c.pairs.push_back({static_cast<int>(i), static_cast<int>(j), share * o.score * std::cbrt(m.ellipsoid.volume())});
    }
    if (c.of_observation[i].empty()) {
      skipped->emplace_back(static_cast<int>(i), "no map object of category " + std::to_string(o.category));
      continue;
    }
    c.usable[i] = 1;
    ++c.num_usable;
  }
  std::stable_sort(c.pairs.begin(), c.pairs.end(),
                   [](const CandidatePair& a, const CandidatePair& b) { return a.quality > b.quality; });
  return c;
}

}  // namespace ellreloc::pipeline
