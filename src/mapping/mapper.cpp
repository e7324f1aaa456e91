#include "ellreloc/mapping/mapper.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>
#include <tuple>

#include "ellreloc/core/mask.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/core/statistics.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/mapping/category_sizes.hpp"

namespace ellreloc {
namespace {

/// For each pixel of the pinhole image (row-major), the index y * width + x of the raw pixel
/// nearest to where the lens imaged it, or -1 outside the raw image.
std::vector<int> rawPixelOfEachPixel(const Lens& lens) {
  const Intrinsics& K = lens.intrinsics;
  std::vector<int> raw(static_cast<size_t>(K.width) * static_cast<size_t>(K.height), -1);
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x) {
      const Eigen::Vector2d p = lens.distortion.distortPixel(K, {x, y});
      const double rx = std::round(p.x()), ry = std::round(p.y());
      if (rx >= 0 && ry >= 0 && rx < K.width && ry < K.height)  // false for NaN too
        raw[static_cast<size_t>(y) * K.width + x] = static_cast<int>(ry) * K.width + static_cast<int>(rx);
    }
  return raw;
}

/// A raw depth image in the pinhole image: each pixel the nearest raw reading (none is
/// interpolated across an object's edge), 0 where no raw pixel maps.
DepthImage pinholeDepth(const DepthImage& raw, const std::vector<int>& raw_pixel) {
  DepthImage out = raw;
  for (size_t i = 0; i < raw_pixel.size(); ++i)
    out.metres[i] = raw_pixel[i] < 0 ? 0.0f : raw.metres[static_cast<size_t>(raw_pixel[i])];
  return out;
}

/// A raw mask in the pinhole image: each pixel the nearest raw one. Only the undistorted
/// outline of the mask's pixel box can hold it (a pixel of margin for the rounding).
RleMask pinholeMask(const RleMask& raw, const std::vector<int>& raw_pixel, const Lens& lens) {
  const std::optional<BinaryMask> crop = decodeMaskCrop(raw);
  const std::optional<Box> region =
      crop ? lens.undistortBox(
                 Box(crop->x0 - 0.5, crop->y0 - 0.5, crop->x0 + crop->width - 0.5, crop->y0 + crop->height - 0.5))
           : std::nullopt;
  if (!region) return emptyRle(raw.height, raw.width);
  // The window: pixels within the outline's bounds; clamped before the cast (the encoder cuts it
  // to the image).
  const auto first = [](double v, int size) { return static_cast<int>(std::ceil(std::clamp(v, -1.0, size + 1.0))); };
  const auto end = [](double v, int size) { return static_cast<int>(std::floor(std::clamp(v, -1.0, size + 1.0))) + 1; };
  const int x_begin = first(region->x1 - 1, raw.width), x_end = end(region->x2 + 1, raw.width);
  const int y_begin = first(region->y1 - 1, raw.height), y_end = end(region->y2 + 1, raw.height);
  return encodeRunsInWindow(raw.height, raw.width, x_begin, x_end, y_begin, y_end, [&](int x, int y) {
    const int r = raw_pixel[static_cast<size_t>(y) * raw.width + x];
    if (r < 0) return false;
    const int lx = r % raw.width - crop->x0, ly = r / raw.width - crop->y0;
    return crop->inside(lx, ly) && crop->at(lx, ly) != 0;
  });
}

/// The views of a young track that place it for the next keyframe's box: its last ones, where
/// a camera that moved on sees it (and bounding the cost of tracks that never fit).
constexpr size_t kPredictionViews = 10;

std::string keyframeText(int index) { return "keyframe " + std::to_string(index); }

bool boxFinite(const Box& b) {
  return std::isfinite(b.x1) && std::isfinite(b.y1) && std::isfinite(b.x2) && std::isfinite(b.y2);
}

/// Two boxes of one image are two objects (Mapper::mergeDuplicateBoxTracks), unless a detector
/// without per-category suppression reported one object twice: a box that nearly coincides with
/// a more confident one of its category (or an equal one listed first) is that second report.
bool reportedTwice(const std::vector<Detection>& detections, size_t j) {
  constexpr double kSameObjectIoU = 0.8;  // above the usual suppression thresholds (0.45-0.7)
  const Detection& d = detections[j];
  for (size_t k = 0; k < detections.size(); ++k) {
    const Detection& other = detections[k];
    if (k == j || other.category_id != d.category_id) continue;
    const bool preferred = other.score > d.score || (other.score == d.score && k < j);
    if (preferred && boxIoU(other.bbox, d.bbox) >= kSameObjectIoU) return true;
  }
  return false;
}

/// The detections' indices in a canonical order: detection score highest first, then category and
/// box (stable for detections equal in all of them), so that which detection starts a track, and
/// so the objects' ids, does not depend on the order a detector lists its boxes in. The keyframe
/// is checked first: every value compared is finite.
std::vector<size_t> canonicalOrder(const std::vector<Detection>& detections) {
  const auto key = [&](size_t i) {
    const Detection& d = detections[i];
    return std::make_tuple(-d.score, d.category_id, d.bbox.x1, d.bbox.y1, d.bbox.x2, d.bbox.y2);
  };
  std::vector<size_t> order(detections.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return key(a) < key(b); });
  return order;
}

/// The 10th and 90th percentiles of the camera depths of an object's occupied voxels
/// (world->camera pose): its depth range in a keyframe, with stray voxels (mask pixels on the
/// background) left out; unbounded without voxels.
std::pair<double, double> depthRange(const VoxelObject& voxels, const Pose& pose) {
  std::vector<double> z;
  for (const Eigen::Vector3d& x : voxels.occupiedCentres()) z.push_back(pose.transform(x).z());
  const double inf = std::numeric_limits<double>::infinity();
  return {quantile(z, 0.1, -inf), quantile(z, 0.9, inf)};
}

/// A voxel object's ellipsoid and cuboid moved by a rigid transform x -> R x + t.
void moveRigidly(MappedObject& m, const Pose& motion) {
  const Ellipsoid& e = m.object.ellipsoid;
  m.object.ellipsoid = Ellipsoid(motion.transform(e.center()), e.axes(), motion.rotation() * e.rotation());
  if (m.cuboid) {
    m.cuboid->center = motion.transform(m.cuboid->center);
    m.cuboid->rotation = motion.rotation() * m.cuboid->rotation;
  }
}

}  // namespace

const char* toString(MappingMode mode) { return mode == MappingMode::Voxel ? "voxel" : "boxes"; }

bool parseMappingMode(const std::string& name, MappingMode* mode) {
  if (name == "voxel") return *mode = MappingMode::Voxel, true;
  if (name == "boxes") return *mode = MappingMode::Boxes, true;
  return false;
}

int Mapper::Track::label() const {
  int best = -1;
  double best_weight = -1.0;
  for (const auto& [category, weight] : labels)
    if (weight > best_weight) best = category, best_weight = weight;
  return best;
}

std::string MapperOptions::validate() const {
  struct Range {
    const char* name;
    double value, lo, hi;
  };
  const double inf = std::numeric_limits<double>::infinity();
  const Range ranges[] = {
      {"voxels.voxel_size", voxels.voxel_size, 1e-6, 1e3},
      {"voxels.hit_probability", voxels.hit_probability, 0, 1},
      {"voxels.miss_probability", voxels.miss_probability, 0, 1},
      {"voxels.clamp_min", voxels.clamp_min, 0, voxels.clamp_max},
      {"voxels.clamp_max", voxels.clamp_max, 0, 1},
      {"voxels.occupied_probability", voxels.occupied_probability, 0, 1},
      {"voxels.depth_tolerance", voxels.depth_tolerance, 0, inf},
      {"voxels.min_depth", voxels.min_depth, 0, voxels.max_depth},
      {"voxels.max_depth", voxels.max_depth, 0, 1e6},
      {"voxels.depth_gate_sigmas", voxels.depth_gate_sigmas, 0, inf},
      {"voxels.depth_gate_min", voxels.depth_gate_min, 0, inf},
      {"voxels.pixel_stride", double(voxels.pixel_stride), 1, 1e6},
      {"voxels.max_voxels", double(voxels.max_voxels), 1, inf},
      {"tracking.label_weight", tracking.label_weight, 0, inf},
      {"tracking.iou_weight", tracking.iou_weight, 0, inf},
      {"tracking.min_iou", tracking.min_iou, 0, 1},
      {"tracking.min_iou_other_label", tracking.min_iou_other_label, 0, 1},
      {"tracking.depth_margin", tracking.depth_margin, 0, inf},
      {"tracking.match_radius", tracking.match_radius, 0, inf},
      {"tracking.match_ratio", tracking.match_ratio, 0, 1},
      {"ellipsoid.low_percentile", ellipsoid.low_percentile, 0, ellipsoid.high_percentile},
      {"ellipsoid.high_percentile", ellipsoid.high_percentile, 0, 1},
      {"ellipsoid.extent_padding", ellipsoid.extent_padding, 0, inf},
      {"boxes.min_views", double(boxes.min_views), 2, inf},
      {"boxes.min_baseline_deg", boxes.min_baseline_deg, 0, 180},
      {"boxes.border_px", boxes.border_px, 0, inf},
      {"boxes.min_median_iou", boxes.min_median_iou, 0, 1},
      {"boxes.max_iterations", double(boxes.max_iterations), 0, inf},
      {"boxes.max_views", double(boxes.max_views), double(boxes.min_views), inf},
      {"boxes.loss_scale", boxes.loss_scale, 1e-6, 1e6},  // finite: the builder refuses others
      {"min_observations", double(min_observations), 1, inf},
      {"prune_probability", prune_probability, 0, 1},
      {"ellipsoid_min_probability", ellipsoid_min_probability, 0, 1},
      {"track_window", double(track_window), 1, inf},
      {"candidate_lifetime", double(candidate_lifetime), 1, inf},
      {"min_score", min_score, -inf, inf},
      {"floor.max_tilt_deg", floor.max_tilt_deg, 0, 90},
      {"floor.inlier_distance", floor.inlier_distance, 0, inf},
      {"floor.min_inlier_share", floor.min_inlier_share, 0, 1},
      {"floor.pixel_stride", double(floor.pixel_stride), 1, 1e6},
      {"floor.iterations", double(floor.iterations), 1, inf},
      {"min_mask_pixels", double(min_mask_pixels), 0, inf},
      {"unit_metres", unit_metres, kMinUnitMetres, kMaxUnitMetres},
  };
  for (const Range& r : ranges)
    if (!(r.value >= r.lo && r.value <= r.hi))  // NaN fails too
      return std::string(r.name) + " is " + std::to_string(r.value) + ", outside [" + std::to_string(r.lo) + ", " +
             std::to_string(r.hi) + "]";
  const auto unit = [](const Eigen::Vector3d& v) { return v.allFinite() && v.norm() > 1e-9; };
  if (!unit(ellipsoid.up)) return "ellipsoid.up is zero or not finite";
  if (!unit(floor.prior_up)) return "floor.prior_up is zero or not finite";
  if (boxes.up && !unit(*boxes.up)) return "boxes.up is zero or not finite";
  if (lens)
    if (const std::string why = lens->whyNotUsable(); !why.empty()) return "lens: " + why;
  if (mode == MappingMode::Voxel && unit_metres != 1.0)
    return "unit_metres must be 1 in voxel mode: depth is in metres";
  return "";
}

Mapper::Mapper(const Intrinsics& K, const MapperOptions& options) : K_(K), options_(options) {
  if (!K.isValid()) throw Error("mapper: invalid camera intrinsics");
  if (const std::string problem = options.validate(); !problem.empty()) throw Error("mapper: " + problem);
  if (options.lens && options.lens->intrinsics != K) throw Error("mapper: lens: its intrinsics are not the camera's");
  if (options.lens && !options.lens->distortion.isZero() && options.mode == MappingMode::Voxel)
    raw_pixel_ = rawPixelOfEachPixel(*options.lens);
}

void Mapper::checkKeyframe(const Pose& pose, const std::vector<Detection>& detections, const DepthImage* depth) const {
  const std::string where = keyframeText(keyframes_);
  if (!pose.isValid()) throw Error(where + ": pose is not a finite rigid transform");
  if (options_.mode == MappingMode::Voxel) {
    if (depth == nullptr) throw Error(where + ": voxel mapping needs a depth image");
    if (depth->width != K_.width || depth->height != K_.height ||
        depth->metres.size() != static_cast<size_t>(K_.width) * static_cast<size_t>(K_.height))
      throw Error(where + ": depth image is " + std::to_string(depth->width) + "x" + std::to_string(depth->height) +
                  ", camera is " + std::to_string(K_.width) + "x" + std::to_string(K_.height));
    const bool any = std::any_of(depth->metres.begin(), depth->metres.end(), [](float d) { return d > 0.0f; });
    if (!any) throw Error(where + ": depth image has no valid reading");
  }
  for (size_t j = 0; j < detections.size(); ++j) {
    const Detection& d = detections[j];
    const std::string det = where + ": detection " + std::to_string(j);
    if (!boxFinite(d.bbox) || !std::isfinite(d.score)) throw Error(det + ": box or score is not finite");
    if (d.mask && (d.mask->width != K_.width || d.mask->height != K_.height))
      throw Error(det + ": mask is " + std::to_string(d.mask->width) + "x" + std::to_string(d.mask->height) +
                  ", camera is " + std::to_string(K_.width) + "x" + std::to_string(K_.height));
    if (d.mask && !d.mask->isConsistent()) throw Error(det + ": mask runs do not add up to its size");
  }
}

KeyframeReport Mapper::addKeyframe(const Pose& pose, const std::vector<Detection>& detections,
                                   const DepthImage* depth) {
  std::unique_lock lock(mutex_);
  checkKeyframe(pose, detections, depth);
  std::optional<DepthImage> pinhole;  // a raw depth image of the lens, in the pinhole image
  if (depth && !raw_pixel_.empty()) depth = &pinhole.emplace(pinholeDepth(*depth, raw_pixel_));
  KeyframeReport report;
  keyframe_poses_.push_back(pose);
  if (options_.mode == MappingMode::Voxel && options_.estimate_up_from_floor) {
    FloorOptions floor = options_.floor;
    floor.prior_up = options_.ellipsoid.up;
    floor.seed = options_.floor.seed + static_cast<uint64_t>(keyframes_);
    if (const auto plane = estimateFloor(K_, pose, *depth, floor)) {
      floor_normal_sum_ += plane->inlier_share * plane->up;
      floor_in_camera_.emplace_back(keyframes_, pose.rotation() * (plane->inlier_share * plane->up));
    }
  }
  const std::vector<size_t> order = canonicalOrder(detections);
  std::vector<Detection> ordered;
  ordered.reserve(order.size());
  for (size_t i : order) ordered.push_back(detections[i]);
  report.object_ids.assign(ordered.size(), -1);  // in the canonical order until the keyframe is done
  std::vector<bool> cut;  // by the raw image's border, for boxes undistorted from it
  if (options_.lens)
    for (Detection& d : ordered) {
      cut.push_back(d.bbox.nearImageBorder(K_.width, K_.height, options_.boxes.border_px));
      d.bbox = options_.lens->undistortBox(d.bbox).value_or(Box());  // an empty box is ignored
      if (d.mask && !raw_pixel_.empty()) d.mask = pinholeMask(*d.mask, raw_pixel_, *options_.lens);
    }
  if (options_.mode == MappingMode::Voxel)
    addVoxelKeyframe(pose, ordered, *depth, &report);
  else
    addBoxKeyframe(pose, ordered, cut, &report);
  // Forget candidates that were not seen again (false detections, passing clutter).
  tracks_.erase(std::remove_if(tracks_.begin(), tracks_.end(),
                               [&](const Track& t) {
                                 return !t.confirmed && keyframes_ - t.last_seen > options_.candidate_lifetime;
                               }),
                tracks_.end());
  ++keyframes_;
  // Each detection's object as it is now (this keyframe's joins done), in the order given.
  std::vector<int> ids(order.size(), -1);
  for (size_t k = 0; k < order.size(); ++k)
    if (report.object_ids[k] >= 0) ids[order[k]] = currentObjectIdLocked(report.object_ids[k]).value_or(-1);
  report.object_ids = std::move(ids);
  return report;
}

void Mapper::observed(Track& track, const Detection& detection) {
  track.labels[detection.category_id] += std::max(detection.score, 1e-3);
  ++track.observations;
  track.last_seen = keyframes_;
  if (track.observations >= options_.min_observations) track.confirmed = true;
  if (track.confirmed && options_.mode == MappingMode::Voxel) track.voxels.prune(options_.prune_probability);
  // Box fits are refitted when the views grew by an eighth since the last fit (and by
  // finish()): refitting at every view would cost quadratic time in the views of an object.
  const bool box_fit_due = options_.mode == MappingMode::Voxel || track.built_views == 0 ||
                           8 * (track.views.size() - track.built_views) >= track.built_views;
  if (track.confirmed && box_fit_due) rebuild(track);
}

void Mapper::finish() {
  std::unique_lock lock(mutex_);
  for (Track& t : tracks_)
    if (t.confirmed && options_.mode == MappingMode::Boxes && t.built_views != t.views.size()) rebuild(t);
}

void Mapper::updateKeyframePoses(const std::vector<Pose>& poses) {
  std::unique_lock lock(mutex_);
  if (poses.size() != keyframe_poses_.size())
    throw Error("mapper: " + std::to_string(poses.size()) + " keyframe pose(s) given for " +
                std::to_string(keyframe_poses_.size()) + " keyframe(s) added");
  for (size_t k = 0; k < poses.size(); ++k)
    if (!poses[k].isValid())
      throw Error("mapper: " + keyframeText(static_cast<int>(k)) + ": pose is not a finite rigid transform");
  if (options_.mode == MappingMode::Voxel && !floor_in_camera_.empty()) {
    floor_normal_sum_.setZero();
    for (const auto& [keyframe, normal] : floor_in_camera_)
      floor_normal_sum_ += poses[static_cast<size_t>(keyframe)].rotation().transpose() * normal;
  }
  // Voxel mode: a point keeps its place in the camera frame of the keyframe that last saw it
  // there, so it moves by that keyframe's correction.
  std::vector<Pose> corrections;
  if (options_.mode == MappingMode::Voxel)
    for (size_t k = 0; k < poses.size(); ++k) corrections.push_back(poses[k].inverse() * keyframe_poses_[k]);
  for (Track& t : tracks_) {
    if (options_.mode == MappingMode::Boxes) {
      for (size_t k = 0; k < t.views.size(); ++k) t.views[k].pose = poses[static_cast<size_t>(t.view_keyframes[k])];
    } else if (!t.integrations.empty()) {
      std::vector<Pose> motions;
      for (const int k : t.integrations) motions.push_back(corrections[static_cast<size_t>(k)]);
      t.voxels.moveWithKeyframes(motions);
      // The ellipsoid moves with the latest keyframe's voxels, so that it is where they are even
      // when the moved voxels no longer build one (rebuild then keeps it).
      if (t.built) moveRigidly(*t.built, motions.back());
    }
    if (t.confirmed) rebuild(t);
  }
  keyframe_poses_ = poses;
  if (options_.mode == MappingMode::Boxes)
    mergeDuplicateBoxTracks();
  else
    mergeDuplicateVoxelTracks(/*every_pair=*/true);
}

BoxSizePrior Mapper::sizePrior(int category) const {
  BoxSizePrior prior;
  const double unit = options_.unit_metres;
  prior.typical_semi_axes = typicalSemiAxes(category) / unit;
  prior.min_axis /= unit;
  prior.max_axis /= unit;
  return prior;
}

std::optional<double> Mapper::estimatedUnitMetres(int min_objects) const {
  std::shared_lock lock(mutex_);
  if (options_.mode != MappingMode::Boxes) return std::nullopt;
  std::vector<double> units;
  for (const Track& t : tracks_) {
    if (!t.confirmed || !t.built || t.built->depth_from_size) continue;
    // The rays alone place the object (the size prior, in the unit assumed, does not), and each
    // box's half-size at that depth is its size in the world's unit: half its two larger axes
    // in metres, for a typical object of its category seen on its broad side.
    const std::optional<Eigen::Vector3d> centre = triangulateBoxCentres(K_, t.views);
    if (!centre) continue;
    std::vector<double> radii;
    for (const BoxView& v : t.views) {
      const double z = v.pose.transform(*centre).z();
      if (z > 0.0) radii.push_back(boxRadiusPerDepth(K_, v.box) * z);
    }
    const double radius = median(radii);
    const Eigen::Vector3d typical = typicalSemiAxes(t.built->object.category);  // smallest first
    if (radius > 0.0) units.push_back(0.5 * (typical(1) + typical(2)) / radius);
  }
  if (static_cast<int>(units.size()) < std::max(1, min_objects)) return std::nullopt;
  return median(units);
}

void Mapper::rebuild(Track& track) const {
  MappedObject m;
  m.object.id = track.id;
  m.object.category = track.label();
  m.object.category_counts = track.labels;
  m.observations = track.observations;
  if (options_.mode == MappingMode::Voxel) {
    EllipsoidBuilderOptions builder = options_.ellipsoid;
    if (floor_normal_sum_.norm() > 0.0) builder.up = floor_normal_sum_.normalized();
    const auto built = buildEllipsoid(track.voxels.occupiedPointMeans(options_.ellipsoid_min_probability), builder);
    if (!built) return;  // keeps the previous ellipsoid, if any
    m.object.ellipsoid = built->ellipsoid;
    m.cuboid = built->cuboid;
    m.voxels = track.voxels.size();
    m.memory_bytes = track.voxels.memoryBytes();
  } else {
    const BoxEllipsoidResult r = buildEllipsoidFromBoxes(K_, track.views, options_.boxes, sizePrior(m.object.category));
    track.built_views = track.views.size();
    if (!r.ok()) {
      track.built.reset();  // boxes that no longer agree: out of the map until they do
      return;
    }
    m.object.ellipsoid = r.ellipsoid;
    m.depth_from_size = r.depth_from_size;
  }
  track.built = m;
}

void Mapper::addVoxelKeyframe(const Pose& pose, const std::vector<Detection>& detections, const DepthImage& depth,
                              KeyframeReport* report) {
  // The keyframe's usable detections with their masks (a box stands in for a missing mask).
  std::vector<size_t> used;
  std::vector<BinaryMask> masks;
  for (size_t j = 0; j < detections.size(); ++j) {
    const Detection& d = detections[j];
    std::optional<BinaryMask> mask =
        d.mask ? decodeMaskCrop(*d.mask) : std::optional<BinaryMask>(maskFromBox(d.bbox, K_.width, K_.height));
    if (d.score < options_.min_score || !mask || mask->count() < options_.min_mask_pixels) {
      ++report->ignored;
      continue;
    }
    used.push_back(j);
    masks.push_back(std::move(*mask));
  }

  const std::vector<int> tracked = trackVoxelDetections2D(pose, detections, used, masks, depth);
  // An object 2D tracking paired with a detection is that detection's in this keyframe: a
  // detector gives one box per object, so no other detection may join it by 3D matching (the
  // detections are taken one at a time, and an earlier one would otherwise find it still free).
  std::vector<char> paired(tracks_.size(), 0);
  for (const int t : tracked)
    if (t >= 0) paired[static_cast<size_t>(t)] = 1;

  for (size_t k = 0; k < used.size(); ++k) {
    const Detection& d = detections[used[k]];
    ++report->used;
    if (tracked[k] >= 0) {
      Track& t = tracks_[static_cast<size_t>(tracked[k])];
      t.voxels.integrate(K_, pose, depth, masks[k]);
      t.integrations.push_back(keyframes_);
      observed(t, d);
      ++report->tracked_2d;
      report->object_ids[used[k]] = t.id;
      continue;
    }
    // 3D matching: the detection's own voxels against every object of its label (eq. 4).
    VoxelObject fresh(options_.voxels);
    fresh.integrate(K_, pose, depth, masks[k]);
    if (fresh.occupiedCount() == 0) {
      --report->used, ++report->ignored;  // no depth inside the mask
      continue;
    }
    // Of several objects that pass it (neighbours of one label), the one that matches best.
    Track* match = nullptr;
    double best = options_.tracking.match_ratio;
    for (size_t i = 0; i < tracks_.size(); ++i) {
      Track& t = tracks_[i];
      if ((i < paired.size() && paired[i]) || t.last_seen == keyframes_ || t.label() != d.category_id) continue;
      const double strength = voxelMatchStrength(fresh, t.voxels, options_.tracking);
      if (strength > best) best = strength, match = &t;
    }
    if (match != nullptr) {
      match->voxels.integrate(K_, pose, depth, masks[k]);
      match->integrations.push_back(keyframes_);
      observed(*match, d);
      ++report->matched_3d;
      report->object_ids[used[k]] = match->id;
      continue;
    }
    Track t;
    t.id = next_id_++;
    t.voxels = std::move(fresh);
    t.integrations = {keyframes_};
    tracks_.push_back(std::move(t));
    observed(tracks_.back(), d);
    ++report->new_objects;
    report->object_ids[used[k]] = tracks_.back().id;
  }
  mergeDuplicateVoxelTracks();
}

std::vector<int> Mapper::trackVoxelDetections2D(const Pose& pose, const std::vector<Detection>& detections,
                                                const std::vector<size_t>& used, const std::vector<BinaryMask>& masks,
                                                const DepthImage& depth) const {
  std::vector<std::pair<size_t, std::vector<Box>>> expected;
  std::vector<std::pair<double, double>> depth_ranges;
  for (size_t i = 0; i < tracks_.size(); ++i) {
    const Track& t = tracks_[i];
    if (keyframes_ - t.last_seen > options_.track_window) continue;
    // An object in the map projects only its voxels near its ellipsoid: a voxel model holds a few
    // strays (mask pixels of a neighbour at the same depth), and a box that reaches them can draw
    // the neighbour's detection to the object once the object itself has left the view.
    if (const auto box = t.voxels.projectedBox(K_, pose, 10, t.built ? &t.built->object.ellipsoid : nullptr)) {
      expected.emplace_back(i, std::vector<Box>{*box});
      depth_ranges.push_back(depthRange(t.voxels, pose));
    }
  }
  PairGate gate = PairGate::Constant(static_cast<long>(expected.size()), static_cast<long>(used.size()), true);
  const double margin = options_.tracking.depth_margin;
  for (size_t k = 0; k < used.size(); ++k) {
    if (!detections[used[k]].mask) continue;  // a box as the mask holds the background too
    // Every positive finite reading: the median only places the detection in depth.
    const std::vector<double> readings =
        maskDepths(depth, masks[k], 1, std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::max());
    if (readings.empty()) continue;
    const double z = median(readings);
    for (size_t i = 0; i < expected.size(); ++i)
      gate(static_cast<long>(i), static_cast<long>(k)) =
          z >= depth_ranges[i].first - margin && z <= depth_ranges[i].second + margin;
  }
  return associate2D(expected, detections, used, gate);
}

void Mapper::mergeDuplicateVoxelTracks(bool every_pair) {
  // A detection that neither 2D tracking nor 3D matching associates starts a new object: a
  // second detection of an object another detection already updated in this keyframe, or an
  // object first seen from a side whose surface has too few voxels near the known ones. Once
  // the new model's surface overlaps the old one, the paper's 3D matching test (eq. 4)
  // recognises them; two objects of one label that pass it are one object, and the younger
  // joins the older. While mapping, only pairs with an object updated in this keyframe can have
  // changed, so only those are tested.
  for (size_t i = 0; i < tracks_.size(); ++i) {
    for (size_t j = i + 1; j < tracks_.size(); ++j) {
      Track &a = tracks_[i], &b = tracks_[j];
      if (!every_pair && a.last_seen != keyframes_ && b.last_seen != keyframes_) continue;
      if (a.label() != b.label()) continue;
      // Centres within the smaller object's mean half-extent, as in mergeDuplicateBoxTracks: an
      // object that wrongly grew over a neighbour of its label must not swallow it whole.
      const Eigen::AlignedBox3d ba = a.voxels.bounds(), bb = b.voxels.bounds();
      if (ba.isEmpty() || bb.isEmpty()) continue;
      const double reach = 0.5 * std::min(ba.sizes().mean(), bb.sizes().mean());
      if ((ba.center() - bb.center()).norm() > reach) continue;
      // A second model of one object lies within the first one's extent (give or take two
      // voxels); two neighbours side by side or stacked make a box longer than either.
      const Eigen::Vector3d larger = ba.volume() >= bb.volume() ? ba.sizes() : bb.sizes();
      if (((ba.merged(bb).sizes() - larger).array() > 2.0 * options_.voxels.voxel_size).any()) continue;
      // Eq. 4 with the radius of one voxel: two models of one surface share voxels, while
      // neighbours a few centimetres apart (cups, books) would pass at the tracking radius.
      TrackingOptions same_surface = options_.tracking;
      same_surface.match_radius = std::min(same_surface.match_radius, options_.voxels.voxel_size * 1.01);
      if (!voxelObjectsMatch(a.voxels, b.voxels, same_surface)) continue;
      a.voxels.absorb(b.voxels);  // b's integrations now count after a's
      a.integrations.insert(a.integrations.end(), b.integrations.begin(), b.integrations.end());
      for (const auto& [category, weight] : b.labels) a.labels[category] += weight;
      a.observations += b.observations;
      a.last_seen = std::max(a.last_seen, b.last_seen);
      a.confirmed = a.confirmed || b.confirmed || a.observations >= options_.min_observations;
      if (a.confirmed) {
        a.voxels.prune(options_.prune_probability);
        rebuild(a);
      }
      forgetJoined(i, j);
      --j;
    }
  }
}

std::vector<int> Mapper::associate2D(const std::vector<std::pair<size_t, std::vector<Box>>>& expected,
                                     const std::vector<Detection>& detections, const std::vector<size_t>& used,
                                     const PairGate& gate) const {
  std::vector<LabelledBox> object_boxes, detection_boxes;
  for (const auto& [track, boxes] : expected)
    object_boxes.push_back({boxes.front(), tracks_[track].label(), {boxes.begin() + 1, boxes.end()}});
  for (size_t j : used) detection_boxes.push_back({detections[j].bbox, detections[j].category_id, {}});
  std::vector<int> tracked = associateBoxes(object_boxes, detection_boxes, options_.tracking, gate);
  for (int& t : tracked)
    if (t >= 0) t = static_cast<int>(expected[static_cast<size_t>(t)].first);
  return tracked;
}

void Mapper::addBoxKeyframe(const Pose& pose, const std::vector<Detection>& detections, const std::vector<bool>& cut,
                            KeyframeReport* report) {
  std::vector<size_t> used;
  for (size_t j = 0; j < detections.size(); ++j) {
    if (detections[j].score < options_.min_score || !(detections[j].bbox.area() > 1.0) ||
        reportedTwice(detections, j)) {
      ++report->ignored;
      continue;
    }
    used.push_back(j);
  }
  // A track's expected box: the projection of its ellipsoid into this keyframe once it has
  // one, else, when seen in the last keyframes, its last box moved with the camera (keyframes
  // far apart move a small object further than its size, and a box left where it was would
  // pair with a neighbour of its label or with nothing), else the projection of a sphere at its
  // triangulated centre.
  std::vector<std::pair<size_t, std::vector<Box>>> expected_boxes;
  for (size_t i = 0; i < tracks_.size(); ++i) {
    const Track& t = tracks_[i];
    std::vector<Box> expected;
    std::optional<Ellipsoid> e;
    if (t.built) {
      e = t.built->object.ellipsoid;
    } else if (keyframes_ - t.last_seen <= options_.track_window) {
      const size_t recent = std::min(kPredictionViews, t.views.size());
      expected = predictedBoxes(K_, {t.views.end() - static_cast<long>(recent), t.views.end()}, sizePrior(t.label()),
                                options_.boxes.min_baseline_deg, pose);
    } else if (const auto c = triangulateBoxCentres(K_, t.views)) {
      const BoxView& last = t.views.back();
      const double z = last.pose.transform(*c).z();
      const double r = boxRadiusPerDepth(K_, last.box) * z;
      if (r > 0.0) e = Ellipsoid(*c, Eigen::Vector3d::Constant(r), Eigen::Matrix3d::Identity());
    }
    if (e) {
      const Projection p = project(*e, K_, pose);
      if (p) expected.push_back(p.ellipse.boundingBox());
    }
    if (!expected.empty()) expected_boxes.emplace_back(i, std::move(expected));
  }
  const std::vector<int> tracked = associate2D(expected_boxes, detections, used);
  for (size_t k = 0; k < used.size(); ++k) {
    const Detection& d = detections[used[k]];
    ++report->used;
    Track* t = nullptr;
    if (tracked[k] >= 0) {
      t = &tracks_[static_cast<size_t>(tracked[k])];
      ++report->tracked_2d;
    } else {
      tracks_.emplace_back();
      t = &tracks_.back();
      t->id = next_id_++;
      ++report->new_objects;
    }
    t->views.push_back({pose, d.bbox, cut.empty() ? std::nullopt : std::optional<bool>(cut[used[k]])});
    t->view_keyframes.push_back(keyframes_);
    observed(*t, d);
    report->object_ids[used[k]] = t->id;
  }
  mergeDuplicateBoxTracks();
}

void Mapper::mergeDuplicateBoxTracks() {
  // Box tracking breaks when a small object moves more than its size between keyframes; the
  // pieces then give nearly the same ellipsoid. Two built objects of one label whose centres
  // lie within the smaller one's mean semi-axis are one object (the younger joins the older),
  // unless a keyframe detected both: a detector gives one box per object, so two boxes of one
  // image are two objects (a book on another, two bottles side by side).
  const auto detected_together = [](const Track& a, const Track& b) {
    // Each track's keyframes ascending (a joined track's views are its own, then the other's).
    std::vector<int> seen_a = a.view_keyframes, seen_b = b.view_keyframes;
    std::sort(seen_a.begin(), seen_a.end());
    std::sort(seen_b.begin(), seen_b.end());
    auto i = seen_a.begin(), j = seen_b.begin();
    while (i != seen_a.end() && j != seen_b.end()) {
      if (*i == *j) return true;
      if (*i < *j)
        ++i;
      else
        ++j;
    }
    return false;
  };
  for (size_t i = 0; i < tracks_.size(); ++i) {
    for (size_t j = i + 1; j < tracks_.size(); ++j) {
      Track &a = tracks_[i], &b = tracks_[j];
      if (!a.built || !b.built || a.label() != b.label()) continue;
      const Ellipsoid &ea = a.built->object.ellipsoid, &eb = b.built->object.ellipsoid;
      const double reach = std::min(ea.axes().mean(), eb.axes().mean());
      if ((ea.center() - eb.center()).norm() > reach || detected_together(a, b)) continue;
      a.views.insert(a.views.end(), b.views.begin(), b.views.end());
      a.view_keyframes.insert(a.view_keyframes.end(), b.view_keyframes.begin(), b.view_keyframes.end());
      for (const auto& [category, weight] : b.labels) a.labels[category] += weight;
      a.observations += b.observations;
      a.last_seen = std::max(a.last_seen, b.last_seen);
      rebuild(a);
      forgetJoined(i, j);
      --j;
    }
  }
}

void Mapper::forgetJoined(size_t i, size_t j) {
  joined_into_[tracks_[j].id] = tracks_[i].id;
  tracks_.erase(tracks_.begin() + static_cast<long>(j));
}

std::optional<int> Mapper::currentObjectId(int id) const {
  std::shared_lock lock(mutex_);
  return currentObjectIdLocked(id);
}

std::optional<int> Mapper::currentObjectIdLocked(int id) const {
  // Joins only go from a younger id to an older one, so the chain ends.
  for (auto next = joined_into_.find(id); next != joined_into_.end(); next = joined_into_.find(id)) id = next->second;
  const bool alive = std::any_of(tracks_.begin(), tracks_.end(), [id](const Track& t) { return t.id == id; });
  return alive ? std::optional<int>(id) : std::nullopt;
}

Eigen::Vector3d Mapper::upLocked() const {
  return floor_normal_sum_.norm() > 0.0 ? floor_normal_sum_.normalized() : options_.ellipsoid.up.normalized();
}

ObjectMap Mapper::map() const {
  std::shared_lock lock(mutex_);
  ObjectMap out;
  for (const Track& t : tracks_)
    if (t.confirmed && t.built) out.objects.push_back(t.built->object);
  // Where the keyframes were taken, measured along the up the ellipsoids stand on (voxel mode,
  // or boxes mode given one), else along the keyframes' mean image-up, whatever the world
  // frame's convention. The relocalizer keeps to it by default, so it is wider than the usual
  // envelope (0.5 m, 20 degrees): a camera may come back lower, higher or more tilted.
  const std::optional<Eigen::Vector3d> up =
      options_.mode == MappingMode::Voxel ? std::optional<Eigen::Vector3d>(upLocked()) : options_.boxes.up;
  out.camera_envelope = CameraEnvelope::fromKeyframes(keyframe_poses_, up, 1.0 / options_.unit_metres, 30.0);
  out.unit_metres = options_.unit_metres;
  return out;
}

std::vector<MappedObject> Mapper::objects() const {
  std::shared_lock lock(mutex_);
  std::vector<MappedObject> out;
  for (const Track& t : tracks_)
    if (t.confirmed && t.built) out.push_back(*t.built);
  return out;
}

MapperStats Mapper::stats() const {
  std::shared_lock lock(mutex_);
  MapperStats s;
  s.keyframes = keyframes_;
  s.up = upLocked();
  for (const Track& t : tracks_) {
    (t.confirmed && t.built ? s.objects : s.candidates) += 1;
    if (t.confirmed && t.built && t.built->depth_from_size) ++s.placed_by_size;
    s.voxels += t.voxels.size();
    s.memory_bytes += t.voxels.memoryBytes();
  }
  return s;
}

}  // namespace ellreloc
