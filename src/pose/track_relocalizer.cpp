#include "ellreloc/pose/track_relocalizer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <unordered_map>

#include "ellreloc/core/evaluation.hpp"
#include "pipeline/candidates.hpp"
#include "pipeline/hypothesis_pool.hpp"
#include "pipeline/pose_scorer.hpp"

namespace ellreloc {

using namespace pipeline;

namespace {

/// The unknown scale is searched in steps of 10% (in its logarithm), up to 4 steps (a factor 1.5)
/// either side of the one the frames' poses propose: a proposal, from poses centimetres to
/// decimetres off, is itself within a few steps of the scale.
constexpr double kScaleStep = 0.1;
constexpr int kScaleSearchSteps = 4;
/// Scales beyond e^+-200 (steps of 2000) are no unit of any odometry: a proposal there is clamped.
constexpr int kMaxScaleStep = 2000;

/// An odometry pose with its translation in map units: the camera centre scaled about the
/// odometry's origin.
Pose scaled(const Pose& odometry, double scale) { return Pose(odometry.rotation(), scale * odometry.translation()); }

/// Map units per odometry unit at a scale step, relative to the step 0's.
double scaleAt(int scale_step) { return std::exp(kScaleStep * scale_step); }

/// The pose of the frame at odometry pose `on` given the pose `pose` of the frame at odometry pose
/// `by` (world -> camera): x_on = O_on O_by^-1 x_by, the odometry's translations times `scale`.
Pose carriedPose(const Pose& on, const Pose& by, double scale, const Pose& pose) {
  return scaled(on, scale) * scaled(by, scale).inverse() * pose;
}

}  // namespace

std::string TrackOptions::validate() const {
  if (max_frames < 1 || max_frames > 100) return "max_frames is not in [1, 100]";
  if (!std::isfinite(min_mean_evidence)) return "min_mean_evidence is not finite";
  if (!(min_margin >= 0.0)) return "min_margin is negative or not a number";
  return "";
}

struct TrackRelocalizer::Frame {
  std::vector<Observation> observations;  // in the canonical order, as the relocalizer scores them
  Candidates candidates;
  std::unique_ptr<PoseScorer> scorer;  // reads `observations` and `candidates`
  Pose odometry;                       // world -> camera in the odometry's frame
  long serial = 0;                     // frames are numbered as they join
  /// A pose its own search found (its pose, then its alternatives), with its costs on the
  /// track's frames. At one scale a frame's pose is a fixed pose of every other frame
  /// (O_j O_k^-1 P_k), so each cost is computed once, when first needed: `costs` holds them by
  /// the frame's serial and the scale step.
  struct Found {
    Pose pose;
    mutable std::unordered_map<std::uint64_t, double> costs;
  };
  std::vector<Found> found;

  /// The cost of `by`'s pose `p` on this frame, carried as `carrying` says (its base is the
  /// track's: the step tells its scales apart).
  double costOf(const Found& p, const Frame& by, const Carrying& carrying) const {
    const std::uint64_t key =
        (static_cast<std::uint64_t>(serial) << 20) ^ static_cast<std::uint64_t>(carrying.scale_step + (1 << 19));
    const auto known = p.costs.find(key);
    if (known != p.costs.end()) return known->second;
    const Pose at = carriedPose(odometry, by.odometry, carrying.scale(), p.pose);
    // An absurd scale of an absurd odometry can leave no finite pose: it explains nothing.
    const double cost = at.isValid() ? scorer->cost(at, kRankingIoUVertices) : std::numeric_limits<double>::infinity();
    p.costs.emplace(key, cost);
    return cost;
  }
};

double TrackRelocalizer::Carrying::scale() const { return base * scaleAt(scale_step); }

TrackRelocalizer::TrackRelocalizer(const ObjectRelocalizer& relocalizer, TrackOptions options)
    : relocalizer_(relocalizer), options_(options) {}

TrackRelocalizer::~TrackRelocalizer() = default;

void TrackRelocalizer::reset() {
  frames_.clear();
  last_scale_step_.reset();
}

TrackRelocalizer::TrackScore TrackRelocalizer::score(const Pose& pose, bool with_evidence,
                                                     const Carrying& carrying) const {
  TrackScore s;
  const double scale = carrying.scale();
  const int vertices = with_evidence ? kReportIoUVertices : kRankingIoUVertices;
  std::vector<ObjectCorrespondence> matches;
  for (size_t k = static_cast<size_t>(carrying.first); k < frames_.size(); ++k) {
    const Frame* frame = frames_[k].get();
    const Pose at = carriedPose(frame->odometry, frames_.back()->odometry, scale, pose);
    s.cost += frame->scorer->cost(at, vertices, with_evidence ? &matches : nullptr);
    if (with_evidence) {
      s.evidence += matchEvidence(matches, frame->candidates.num_usable, relocalizer_.options().acceptance);
      s.matches += static_cast<int>(matches.size());
    }
  }
  return s;
}

void TrackRelocalizer::join(const std::vector<Observation>& observations, const Pose& odometry_pose,
                            const RelocalizationResult& own) {
  const ObjectMap& map = relocalizer_.map();
  const RelocalizerOptions& options = relocalizer_.options();
  auto frame = std::make_unique<Frame>();
  for (const int i : canonicalOrder(observations)) frame->observations.push_back(observations[static_cast<size_t>(i)]);
  std::vector<std::pair<int, std::string>> skipped;
  frame->candidates =
      collectCandidates(frame->observations, map, options.scoring, options.search.max_candidate_pairs, &skipped);
  frame->scorer = std::make_unique<PoseScorer>(frame->observations, frame->candidates, map, relocalizer_.intrinsics(),
                                               options.scoring);
  frame->odometry = odometry_pose;
  frame->serial = next_serial_++;
  if (own.status == RelocalizationStatus::Success || own.status == RelocalizationStatus::LowEvidence) {
    frame->found.push_back({own.pose, {}});
    for (const ScoredPose& a : own.alternatives) frame->found.push_back({a.pose, {}});
  }
  frames_.push_back(std::move(frame));
  while (size() > options_.max_frames) frames_.pop_front();
}

std::vector<TrackRelocalizer::Carried> TrackRelocalizer::rankedPoses(const Carrying& carrying) const {
  const double scale = carrying.scale();
  const double unit = relocalizer_.map().unit_metres;
  const Pose newest = scaled(frames_.back()->odometry, scale);
  std::vector<Carried> carried;
  for (int k = size() - 1; k >= carrying.first; --k) {  // newest first: of equal costs, the newest frame's pose wins
    const Frame& f = *frames_[static_cast<size_t>(k)];
    const Pose back = (scaled(f.odometry, scale) * newest.inverse()).inverse();  // the frame's pose -> the newest's
    for (const Frame::Found& p : f.found) {
      const Pose pose = back * p.pose;
      if (!pose.isValid()) continue;
      if (std::any_of(carried.begin(), carried.end(),
                      [&](const Carried& c) { return sameNeighbourhood(c.pose, pose, unit); }))
        continue;
      double cost = 0.0;  // over the frames carried
      for (int j = carrying.first; j < size(); ++j) cost += frames_[static_cast<size_t>(j)]->costOf(p, f, carrying);
      carried.push_back({pose, size() - 1 - k, cost});
    }
  }
  std::stable_sort(carried.begin(), carried.end(), [](const Carried& a, const Carried& b) { return a.cost < b.cost; });
  return carried;
}

double TrackRelocalizer::proposedScale() const {
  // Two frames whose own poses turn as the odometry does (within 10 degrees) and move the way it
  // does in the first frame's camera (within 20 degrees) propose the ratio of the distances
  // between their cameras. Only pairs far apart for the track (a quarter of its widest span in
  // the odometry) and in the map (20 cm, beyond the poses' errors) propose. The proposals
  // weigh as their odometry baselines; the heaviest cluster (within 10%) gives the scale.
  double widest = 0.0;
  for (const auto& a : frames_)
    for (const auto& b : frames_) widest = std::max(widest, (a->odometry.center() - b->odometry.center()).norm());
  if (!(widest > 0.0)) return 0.0;
  struct Proposal {
    double log_scale, weight;
  };
  std::vector<Proposal> proposals;
  for (size_t j = 0; j < frames_.size(); ++j)
    for (size_t k = j + 1; k < frames_.size(); ++k) {
      const Pose& oj = frames_[j]->odometry;
      const Pose& ok = frames_[k]->odometry;
      const Eigen::Vector3d moved = ok.center() - oj.center();
      const double baseline = moved.norm();
      if (baseline < 0.25 * widest) continue;
      const Eigen::Matrix3d turned = ok.rotation() * oj.rotation().transpose();
      const Eigen::Vector3d way = oj.rotation() * moved / baseline;  // in frame j's camera
      for (const Frame::Found& a : frames_[j]->found)
        for (const Frame::Found& b : frames_[k]->found) {
          const Eigen::Vector3d map_moved = b.pose.center() - a.pose.center();
          const double distance = map_moved.norm();
          if (distance < 0.2) continue;
          if (rotationErrorDeg(b.pose.rotation() * a.pose.rotation().transpose(), turned) > 10.0) continue;
          if ((a.pose.rotation() * map_moved / distance).dot(way) < std::cos(20.0 * M_PI / 180.0)) continue;
          const double log_scale = std::log(distance / baseline);
          if (std::isfinite(log_scale)) proposals.push_back({log_scale, baseline / widest});
        }
    }
  // The cluster of each proposal: those within 0.1 of it in log scale, found in sorted order (a
  // long track of many poses has thousands of proposals).
  std::sort(proposals.begin(), proposals.end(),
            [](const Proposal& a, const Proposal& b) { return a.log_scale < b.log_scale; });
  double best_weight = 0.0, best_sum = 0.0, weight = 0.0, sum = 0.0;
  size_t lo = 0, hi = 0;  // the cluster of proposal i: [lo, hi)
  for (const Proposal& p : proposals) {
    for (; hi < proposals.size() && proposals[hi].log_scale - p.log_scale < 0.1; ++hi)
      weight += proposals[hi].weight, sum += proposals[hi].weight * proposals[hi].log_scale;
    for (; p.log_scale - proposals[lo].log_scale >= 0.1; ++lo)
      weight -= proposals[lo].weight, sum -= proposals[lo].weight * proposals[lo].log_scale;
    if (weight > best_weight) best_weight = weight, best_sum = sum;
  }
  return best_weight > 0.0 ? std::exp(best_sum / best_weight) : 0.0;
}

TrackRelocalizer::Carrying TrackRelocalizer::chooseCarrying(std::vector<Carried>* ranked) {
  if (options_.metric_odometry) {
    const Carrying metric{0, 0, true, 1.0 / relocalizer_.map().unit_metres};
    *ranked = rankedPoses(metric);
    return metric;
  }
  const double proposed = proposedScale();
  const std::optional<int> centre =
      proposed > 0.0 ? std::optional<int>(static_cast<int>(std::lround(
                           std::clamp(std::log(proposed) / kScaleStep, -1.0 * kMaxScaleStep, 1.0 * kMaxScaleStep))))
                     : last_scale_step_;
  if (!centre) {  // no scale yet: the newest frame's poses on it alone
    const Carrying alone{0, size() - 1, false};
    *ranked = rankedPoses(alone);
    return alone;
  }
  Carrying best{*centre, 0};
  ranked->clear();
  for (int d = 0; d <= 2 * kScaleSearchSteps; ++d) {  // centre, -1, +1, -2, ...: of equal costs, the nearer
    const Carrying c{*centre + (d % 2 == 0 ? d / 2 : -(d + 1) / 2), 0};
    std::vector<Carried> poses = rankedPoses(c);
    if (!poses.empty() && (ranked->empty() || poses.front().cost < ranked->front().cost)) {
      best = c;
      *ranked = std::move(poses);
    }
  }
  last_scale_step_ = best.scale_step;
  return best;
}

TrackResult TrackRelocalizer::add(const std::vector<Observation>& observations, const Pose& odometry_pose,
                                  const std::optional<GravityPrior>& gravity) {
  const auto start = std::chrono::steady_clock::now();
  TrackResult out;
  out.frames = size();
  const auto invalid = [&](const std::string& why) {
    out.result.status = RelocalizationStatus::InvalidInput;
    out.result.reason = why;
    return out;
  };
  if (const std::string bad = options_.validate(); !bad.empty()) return invalid("invalid track options: " + bad);
  if (!odometry_pose.isValid()) return invalid("invalid odometry pose (non-finite, or not a rotation)");
  out.result = relocalizer_.relocalizeUnpolished(observations, gravity);
  if (out.result.status == RelocalizationStatus::InvalidInput) return out;
  join(observations, odometry_pose, out.result);

  std::vector<Carried> ranked;
  const Carrying carrying = chooseCarrying(&ranked);
  out.frames = size() - carrying.first;
  out.scale = carrying.known ? carrying.scale() : 0.0;
  out.candidates = static_cast<int>(ranked.size());
  if (!ranked.empty()) {  // else no frame of the track gave a pose: this frame's own answer says why
    out.found_by = ranked.front().found_by;
    // The best refined on the newest frame, kept when that explains the track no worse.
    Pose pose = ranked.front().pose;
    const RelocalizationResult refined = relocalizer_.refineFrom(observations, pose);
    const bool keep_refined =
        refined.refined && refined.pose.isValid() && score(refined.pose, false, carrying).cost <= ranked.front().cost;
    if (keep_refined) pose = refined.pose;
    report(observations, pose, ranked, carrying, &out);
    out.result.refined = keep_refined;
  }
  out.result.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

void TrackRelocalizer::report(const std::vector<Observation>& observations, const Pose& pose,
                              const std::vector<Carried>& ranked, const Carrying& carrying, TrackResult* out) const {
  const RelocalizationResult at = relocalizer_.scorePose(observations, pose);
  RelocalizationResult& result = out->result;
  result.pose = pose;
  result.inliers = at.inliers;
  result.cost = at.cost;
  result.mean_overlap = at.mean_overlap;
  result.evidence = at.evidence;
  const TrackScore track = score(pose, true, carrying);
  out->track_cost = track.cost;
  out->track_evidence = track.evidence;
  out->track_matches = track.matches;

  // The other answers: carried poses elsewhere, each away from every cheaper one too.
  result.alternatives.clear();
  const double unit = relocalizer_.map().unit_metres;
  const auto elsewhere = [unit](const Pose& a, const Pose& b) { return !poseError(a, b, unit).valid(); };
  for (const Carried& c : ranked) {
    if (!elsewhere(c.pose, pose)) continue;
    if (std::any_of(result.alternatives.begin(), result.alternatives.end(),
                    [&](const ScoredPose& a) { return !elsewhere(c.pose, a.pose); }))
      continue;
    result.alternatives.push_back({c.pose, c.cost});
  }
  result.rival.reset();
  result.margin = std::numeric_limits<double>::infinity();
  if (!result.alternatives.empty()) {
    result.rival = result.alternatives.front().pose;
    result.margin = result.alternatives.front().cost - ranked.front().cost;
  }

  const RelocalizerOptions& options = relocalizer_.options();
  const AcceptanceOptions& acceptance = options.acceptance;
  char reason[160] = "";
  if (track.matches < options.scoring.min_inliers) {
    result.status = RelocalizationStatus::NoConsistentHypothesis;
    std::snprintf(reason, sizeof reason, "the track's best pose explains %d observation(s) over %d frame(s)",
                  track.matches, out->frames);
  } else if (acceptance.enabled && track.evidence < acceptance.min_evidence) {
    result.status = RelocalizationStatus::LowEvidence;
    std::snprintf(reason, sizeof reason, "track evidence %.2f below %.2f: %d observation(s) explained over %d frame(s)",
                  track.evidence, acceptance.min_evidence, track.matches, out->frames);
  } else if (acceptance.enabled && track.evidence < options_.min_mean_evidence * out->frames) {
    result.status = RelocalizationStatus::LowEvidence;
    std::snprintf(reason, sizeof reason, "track evidence %.2f over %d frame(s): below %.2f per frame", track.evidence,
                  out->frames, options_.min_mean_evidence);
  } else if (acceptance.enabled && result.margin < options_.min_margin) {
    result.status = RelocalizationStatus::LowEvidence;
    std::snprintf(reason, sizeof reason, "track margin %.2f below %.2f: another pose explains the track almost as well",
                  result.margin, options_.min_margin);
  } else {
    result.status = RelocalizationStatus::Success;
  }
  result.reason = reason;
}

}  // namespace ellreloc
