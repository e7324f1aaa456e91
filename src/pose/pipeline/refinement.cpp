#include "refinement.hpp"

#include <algorithm>
#include <atomic>
#include <thread>

#include "ellreloc/core/evaluation.hpp"

namespace ellreloc::pipeline {

namespace {

/// The prior joins a refinement where the objects leave the tilt weakly constrained.
std::optional<GravityPrior> refinementGravity(const RefinementContext& c, size_t matched) {
  return matched < 3 || c.options.gravity.in_every_refinement ? c.gravity : std::nullopt;
}

/// Takes a refined pose, its cost and matches in place of the chosen one's.
void adopt(const Pose& pose, double cost, std::vector<ObjectCorrespondence> matches, ChosenPose* chosen) {
  chosen->margin += chosen->cost - cost;  // the rivals keep their costs
  chosen->pose = pose;
  chosen->cost = cost;
  chosen->matches = std::move(matches);
  chosen->refined = true;
}

}  // namespace

ChosenPose refineRounds(const Pose& start, PoseScorer& scorer, const RefinementContext& c) {
  ChosenPose h;
  h.pose = start;
  h.cost = scorer.cost(start, kReportIoUVertices, &h.matches);
  const RefinementStageOptions& opt = c.options.refinement;
  for (int round = 0; round < opt.rounds && opt.enabled; ++round) {
    if (static_cast<int>(h.matches.size()) < (c.gravity ? 1 : 2)) break;
    const RefinementResult r =
        refinePose(c.K, h.pose, ellipseMatches(h.matches, c), {}, opt.refiner, refinementGravity(c, h.matches.size()));
    if (r.fell_back || !c.gate.admits(r.pose)) break;
    std::vector<ObjectCorrespondence> rematched;
    const double refined_cost = scorer.cost(r.pose, kReportIoUVertices, &rematched);
    if (refined_cost > h.cost) break;
    const bool more = rematched.size() > h.matches.size();
    h.pose = r.pose;
    h.cost = refined_cost;
    h.refined = true;
    h.matches = std::move(rematched);
    if (!more) break;
  }
  return h;
}

std::vector<EllipseMatch> ellipseMatches(const std::vector<ObjectCorrespondence>& matches,
                                         const RefinementContext& context) {
  std::vector<EllipseMatch> out;
  out.reserve(matches.size());
  for (const ObjectCorrespondence& m : matches)
    out.push_back(refinerMatch(context.observations[static_cast<size_t>(m.observation)],
                               context.map.objects[static_cast<size_t>(m.object)].ellipsoid,
                               context.options.refinement));
  return out;
}

ChosenPose refineHypotheses(const HypothesisPool& pool, const Pose& search_best,
                            const std::vector<PoseScorer*>& scorers, const RefinementContext& context,
                            size_t max_refined) {
  std::vector<Pose> starts;
  for (const ScoredPose& h : pool.entries()) {
    if (h.cost > pool.best().cost + context.options.refinement.cost_margin) break;  // ascending costs
    if (starts.size() == max_refined) break;
    starts.push_back(h.pose);
  }
  // Each start is refined on its own (on as many threads as there are scorers); the results
  // are then compared in pool order, so the choice does not depend on the threads.
  std::vector<ChosenPose> refined(starts.size());
  std::atomic<size_t> next{0};
  const auto work = [&](size_t t) {
    for (size_t i = next++; i < starts.size(); i = next++) refined[i] = refineRounds(starts[i], *scorers[t], context);
  };
  std::vector<std::thread> helpers;
  for (size_t t = 1; t < std::min(scorers.size(), starts.size()); ++t) helpers.emplace_back(work, t);
  work(0);
  for (std::thread& h : helpers) h.join();
  // When the search's best pose is the pool's first (nearly always), its refinement starts from
  // the cost and matches it would be given here and keeps them unless refined to a cost as low
  // (refineRounds), which the comparison below would take anyway: they are reused.
  ChosenPose best;
  if (!starts.empty() && starts[0].rotation() == search_best.rotation() &&
      starts[0].translation() == search_best.translation()) {
    best = refined[0];
  } else {
    best.pose = search_best;
    best.cost = scorers.front()->cost(search_best, kReportIoUVertices, &best.matches);
  }
  for (const ChosenPose& candidate : refined)
    if (candidate.cost < best.cost || (candidate.refined && candidate.cost <= best.cost)) {
      best.pose = candidate.pose;
      best.cost = candidate.cost;
      best.refined = candidate.refined;
      best.matches = candidate.matches;  // refineRounds' matches are its pose's
    }
  // A rival that refines to another answer almost as well means look-alike objects or a
  // symmetric layout: the frame cannot tell the two apart. Starts that refine to the same
  // answer count once, at the cost of the cheapest.
  std::vector<const ChosenPose*> by_cost;
  for (const ChosenPose& candidate : refined) by_cost.push_back(&candidate);
  std::stable_sort(by_cost.begin(), by_cost.end(),
                   [](const ChosenPose* a, const ChosenPose* b) { return a->cost < b->cost; });
  const double unit = context.map.unit_metres;
  const auto elsewhere = [unit](const Pose& a, const Pose& b) { return !poseError(a, b, unit).valid(); };
  for (const ChosenPose* candidate : by_cost) {
    if (!elsewhere(candidate->pose, best.pose)) continue;
    const bool seen = std::any_of(best.alternatives.begin(), best.alternatives.end(),
                                  [&](const ScoredPose& a) { return !elsewhere(candidate->pose, a.pose); });
    if (!seen) best.alternatives.push_back({candidate->pose, candidate->cost});
  }
  if (!best.alternatives.empty()) best.margin = best.alternatives.front().cost - best.cost;
  return best;
}

ChosenPose polishPose(ChosenPose chosen, PoseScorer& scorer, const RefinementContext& c) {
  const RefinementStageOptions& opt = c.options.refinement;
  // Three matches at least: with fewer the pose rests on each of them, and none is an outlier.
  if (!opt.enabled || !(opt.polish_loss_scale > 0) || chosen.matches.size() < 3) return chosen;
  RefinerOptions tight = opt.refiner;
  tight.object_loss_scale = opt.polish_loss_scale;
  const RefinementResult r = refinePose(c.K, chosen.pose, ellipseMatches(chosen.matches, c), {}, tight,
                                        refinementGravity(c, chosen.matches.size()));
  if (r.fell_back || !c.gate.admits(r.pose)) return chosen;
  std::vector<ObjectCorrespondence> rematched;
  const double cost = scorer.cost(r.pose, kReportIoUVertices, &rematched);
  if (cost <= chosen.cost) adopt(r.pose, cost, std::move(rematched), &chosen);
  return chosen;
}

ChosenPose refineWithPoints(ChosenPose chosen, const std::vector<PointMatch>& points, PoseScorer& scorer,
                            const RefinementContext& c) {
  if (points.empty() || !c.options.refinement.enabled || chosen.matches.empty()) return chosen;
  const RefinementResult r = refinePose(c.K, chosen.pose, ellipseMatches(chosen.matches, c), points,
                                        c.options.refinement.refiner, refinementGravity(c, chosen.matches.size()));
  if (r.fell_back) return chosen;
  std::vector<ObjectCorrespondence> with_points;
  const double cost = scorer.cost(r.pose, kReportIoUVertices, &with_points);
  if (with_points.size() >= chosen.matches.size() && c.gate.admits(r.pose))
    adopt(r.pose, cost, std::move(with_points), &chosen);
  return chosen;
}

}  // namespace ellreloc::pipeline
