#include "ellreloc/pose/track_relocalizer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "ellreloc/core/evaluation.hpp"
#include "pipeline/candidates.hpp"
#include "pipeline/hypothesis_pool.hpp"
#include "pipeline/pose_scorer.hpp"

namespace ellreloc {

using namespace pipeline;

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
  /// A pose its own search found (its pose, then its alternatives), with its cost on each frame
  /// of the track: `costs[j - first]` on frame number j. A frame's pose is a fixed pose of every
  /// other frame (O_j O_k^-1 P_k), so each cost is computed once, when the later of the two joins.
  struct Found {
    Pose pose;
    std::vector<double> costs;
  };
  std::vector<Found> found;
  long first = 0;  // the number of the oldest frame of the track when this one joined
};

TrackRelocalizer::TrackRelocalizer(const ObjectRelocalizer& relocalizer, TrackOptions options)
    : relocalizer_(relocalizer), options_(options) {}

TrackRelocalizer::~TrackRelocalizer() = default;

void TrackRelocalizer::reset() { frames_.clear(); }

TrackRelocalizer::TrackScore TrackRelocalizer::score(const Pose& pose, bool with_evidence) const {
  TrackScore s;
  const Pose& newest = frames_.back()->odometry;
  const int vertices = with_evidence ? kReportIoUVertices : kRankingIoUVertices;
  std::vector<ObjectCorrespondence> matches;
  for (const std::unique_ptr<Frame>& frame : frames_) {
    // x_frame = odometry_frame odometry_newest^-1 x_newest, so the frame's pose is that times `pose`.
    const Pose at = frame->odometry * newest.inverse() * pose;
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

  // The costs that are new: the older frames' poses on this frame, this frame's on every frame.
  Frame& added = *frames_.back();
  added.first = frames_.front()->serial;
  const auto cost = [](const Frame& on, const Frame& by, const Pose& pose) {  // `by`'s pose, on frame `on`
    return on.scorer->cost(on.odometry * by.odometry.inverse() * pose, kRankingIoUVertices);
  };
  for (const std::unique_ptr<Frame>& f : frames_) {
    if (f.get() == &added) continue;
    for (Frame::Found& p : f->found) p.costs.push_back(cost(added, *f, p.pose));
  }
  for (Frame::Found& p : added.found)
    for (const std::unique_ptr<Frame>& f : frames_) p.costs.push_back(cost(*f, added, p.pose));
}

std::vector<TrackRelocalizer::Carried> TrackRelocalizer::rankedPoses() const {
  const Pose& newest = frames_.back()->odometry;
  const long oldest = frames_.front()->serial;
  std::vector<Carried> carried;
  for (int k = size() - 1; k >= 0; --k) {  // newest first: of equal costs, the newest frame's pose wins
    const Frame& f = *frames_[static_cast<size_t>(k)];
    const Pose back = (f.odometry * newest.inverse()).inverse();  // the frame's pose -> the newest's
    for (const Frame::Found& p : f.found) {
      const Pose pose = back * p.pose;
      if (std::any_of(carried.begin(), carried.end(),
                      [&](const Carried& c) { return sameNeighbourhood(c.pose, pose); }))
        continue;
      double cost = 0.0;  // over the frames the track holds now
      for (long j = oldest; j <= frames_.back()->serial; ++j) cost += p.costs[static_cast<size_t>(j - f.first)];
      carried.push_back({pose, size() - 1 - k, cost});
    }
  }
  std::stable_sort(carried.begin(), carried.end(), [](const Carried& a, const Carried& b) { return a.cost < b.cost; });
  return carried;
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
  out.result = relocalizer_.relocalize(observations, {}, gravity);
  if (out.result.status == RelocalizationStatus::InvalidInput) return out;
  join(observations, odometry_pose, out.result);
  out.frames = size();

  const std::vector<Carried> ranked = rankedPoses();
  out.candidates = static_cast<int>(ranked.size());
  if (!ranked.empty()) {  // else no frame of the track gave a pose: this frame's own answer says why
    out.found_by = ranked.front().found_by;
    // The best refined on the newest frame, kept when that explains the track no worse.
    Pose pose = ranked.front().pose;
    const RelocalizationResult refined = relocalizer_.refineFrom(observations, pose);
    const bool keep_refined =
        refined.refined && refined.pose.isValid() && score(refined.pose, false).cost <= ranked.front().cost;
    if (keep_refined) pose = refined.pose;
    report(observations, pose, ranked, &out);
    out.result.refined = keep_refined;
  }
  out.result.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

void TrackRelocalizer::report(const std::vector<Observation>& observations, const Pose& pose,
                              const std::vector<Carried>& ranked, TrackResult* out) const {
  const RelocalizationResult at = relocalizer_.scorePose(observations, pose);
  RelocalizationResult& result = out->result;
  result.pose = pose;
  result.inliers = at.inliers;
  result.cost = at.cost;
  result.mean_overlap = at.mean_overlap;
  result.evidence = at.evidence;
  const TrackScore track = score(pose, true);
  out->track_cost = track.cost;
  out->track_evidence = track.evidence;
  out->track_matches = track.matches;

  // The other answers: carried poses elsewhere, each away from every cheaper one too.
  result.alternatives.clear();
  const auto elsewhere = [](const Pose& a, const Pose& b) { return !poseError(a, b).valid(); };
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
