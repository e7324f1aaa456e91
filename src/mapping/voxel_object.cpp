#include "ellreloc/mapping/voxel_object.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>

#include "ellreloc/core/statistics.hpp"
#include "ellreloc/error.hpp"

namespace ellreloc {
namespace {

constexpr int kKeyBits = 21;
constexpr int kKeyOffset = 1 << (kKeyBits - 1);  // keys span [-2^20, 2^20) voxels per axis
constexpr uint64_t kKeyMask = (uint64_t{1} << kKeyBits) - 1;

double logit(double p) { return std::log(p / (1.0 - p)); }

/// The splitmix64 finaliser: packed keys are far from random, their low bits nearly constant.
uint64_t hashOf(uint64_t k) {
  k ^= k >> 30;
  k *= 0xbf58476d1ce4e5b9ULL;
  k ^= k >> 27;
  k *= 0x94d049bb133111ebULL;
  return k ^ (k >> 31);
}

bool inMask(const BinaryMask& mask, int x, int y) {
  const int lx = x - mask.x0, ly = y - mask.y0;
  return mask.inside(lx, ly) && mask.at(lx, ly) != 0;
}

void checkInputs(const Intrinsics& K, const Pose& pose, const DepthImage& depth, const BinaryMask& mask) {
  if (!K.isValid()) throw Error("voxel integration: invalid camera intrinsics");
  if (!pose.isValid()) throw Error("voxel integration: keyframe pose is not a finite rigid transform");
  if (depth.width != K.width || depth.height != K.height ||
      depth.metres.size() != static_cast<size_t>(depth.width) * static_cast<size_t>(depth.height))
    throw Error("voxel integration: depth image is " + std::to_string(depth.width) + "x" +
                std::to_string(depth.height) + ", camera is " + std::to_string(K.width) + "x" +
                std::to_string(K.height));
  if (mask.image_width != depth.width || mask.image_height != depth.height ||
      mask.data.size() != static_cast<size_t>(mask.width) * static_cast<size_t>(mask.height))
    throw Error("voxel integration: mask is for a " + std::to_string(mask.image_width) + "x" +
                std::to_string(mask.image_height) + " image, depth is " + std::to_string(depth.width) + "x" +
                std::to_string(depth.height));
}

}  // namespace

BinaryMask majorityFiltered(const BinaryMask& mask) {
  BinaryMask out = mask;
  for (int y = 0; y < mask.height; ++y)
    for (int x = 0; x < mask.width; ++x) {
      int votes = 0;  // pixels outside the crop count as 0, like the rest of the image
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) votes += mask.inside(x + dx, y + dy) && mask.at(x + dx, y + dy) != 0;
      out.at(x, y) = votes >= 5 ? 1 : 0;
    }
  return out;
}

std::vector<double> maskDepths(const DepthImage& depth, const BinaryMask& mask, int stride, double min_depth,
                               double max_depth) {
  std::vector<double> d;
  for (int ly = 0; ly < mask.height; ly += stride)
    for (int lx = 0; lx < mask.width; lx += stride) {
      if (mask.at(lx, ly) == 0) continue;
      const double v = depth.at(lx + mask.x0, ly + mask.y0);
      if (v >= min_depth && v <= max_depth) d.push_back(v);
    }
  return d;
}

std::pair<double, double> VoxelObject::depthGate(const DepthImage& depth, const BinaryMask& mask, int stride) const {
  std::pair<double, double> range(options_.min_depth, options_.max_depth);
  if (!(options_.depth_gate_sigmas > 0.0)) return range;
  std::vector<double> d = maskDepths(depth, mask, stride, options_.min_depth, options_.max_depth);
  if (d.empty()) return range;
  const double centre = median(d);
  for (double& v : d) v = std::abs(v - centre);
  const double sigma = 1.4826 * median(d);  // the MAD of a Gaussian is 0.6745 sigma
  const double half = std::max(options_.depth_gate_min, options_.depth_gate_sigmas * sigma);
  return {std::max(range.first, centre - half), std::min(range.second, centre + half)};
}

inline uint64_t VoxelObject::pack(int x, int y, int z) {
  return (static_cast<uint64_t>(x + kKeyOffset) << (2 * kKeyBits)) |
         (static_cast<uint64_t>(y + kKeyOffset) << kKeyBits) | static_cast<uint64_t>(z + kKeyOffset);
}

inline Eigen::Vector3i VoxelObject::unpack(uint64_t key) {
  return Eigen::Vector3i(static_cast<int>((key >> (2 * kKeyBits)) & kKeyMask) - kKeyOffset,
                         static_cast<int>((key >> kKeyBits) & kKeyMask) - kKeyOffset,
                         static_cast<int>(key & kKeyMask) - kKeyOffset);
}

inline std::optional<uint64_t> VoxelObject::keyOf(const Eigen::Vector3d& x_w) const {
  const Eigen::Vector3d g = (x_w / options_.voxel_size).array().floor();
  if (!g.allFinite() || g.cwiseAbs().maxCoeff() >= kKeyOffset - 1) return std::nullopt;
  return pack(static_cast<int>(g(0)), static_cast<int>(g(1)), static_cast<int>(g(2)));
}

inline Eigen::Vector3d VoxelObject::centreOf(uint64_t key) const {
  return (unpack(key).cast<double>().array() + 0.5).matrix() * options_.voxel_size;
}

void VoxelObject::addToMean(Voxel& v, const Eigen::Vector3d& offset, long count) {
  constexpr long kMaxPoints = 65535;
  if (count <= 0) return;
  const long total = std::min(kMaxPoints, static_cast<long>(v.points) + count);
  const double weight = static_cast<double>(count) / static_cast<double>(std::max<long>(total, count));
  for (int k = 0; k < 3; ++k) {
    const double mean = v.mean[k] + weight * (offset(k) * kMeanUnits - v.mean[k]);
    v.mean[k] = static_cast<int16_t>(std::lround(std::clamp(mean, -32767.0, 32767.0)));
  }
  v.points = static_cast<uint16_t>(total);
}

VoxelObject::VoxelObject(const VoxelOptions& options)
    : options_(options), occupied_log_odds_(static_cast<float>(logit(options.occupied_probability))) {}

inline bool VoxelObject::occupied(const Voxel& v) const { return v.log_odds >= occupied_log_odds_; }

size_t VoxelObject::slotOf(uint64_t key) const {
  const size_t mask = slots_.size() - 1;
  size_t s = hashOf(key) & mask;
  while (slots_[s] != 0 && keys_[slots_[s] - 1] != key) s = (s + 1) & mask;
  return s;
}

long VoxelObject::indexOf(uint64_t key) const {
  if (slots_.empty()) return -1;
  const uint32_t slot = slots_[slotOf(key)];
  return slot == 0 ? -1 : static_cast<long>(slot - 1);
}

size_t VoxelObject::indexOrAdd(uint64_t key, bool* added) {
  if (2 * (voxels_.size() + 1) > slots_.size()) {
    if (voxels_.size() >= std::numeric_limits<uint32_t>::max() / 4)
      throw Error("voxel object: more than 2^30 voxels; set VoxelOptions::max_voxels");
    reindex(2 * slots_.size());
  }
  const size_t s = slotOf(key);
  *added = slots_[s] == 0;
  if (!*added) return slots_[s] - 1;
  keys_.push_back(key);
  voxels_.emplace_back();
  slots_[s] = static_cast<uint32_t>(voxels_.size());
  return voxels_.size() - 1;
}

void VoxelObject::reindex(size_t min_slots) {
  size_t n = 16;
  while (n < std::max(min_slots, 2 * (keys_.size() + 1))) n *= 2;
  slots_.assign(n, 0);
  for (size_t i = 0; i < keys_.size(); ++i) slots_[slotOf(keys_[i])] = static_cast<uint32_t>(i + 1);
}

template <class Keep>
size_t VoxelObject::keepIf(Keep keep) {
  size_t kept = 0;
  for (size_t i = 0; i < voxels_.size(); ++i)
    if (keep(voxels_[i])) keys_[kept] = keys_[i], voxels_[kept] = voxels_[i], ++kept;
  const size_t removed = voxels_.size() - kept;
  if (removed == 0) return 0;
  keys_.resize(kept);
  voxels_.resize(kept);
  reindex(0);
  return removed;
}

VoxelUpdate VoxelObject::integrate(const Intrinsics& K, const Pose& pose, const DepthImage& depth,
                                   const BinaryMask& raw_mask) {
  checkInputs(K, pose, depth, raw_mask);
  const BinaryMask filtered = options_.mask_majority_filter ? majorityFiltered(raw_mask) : BinaryMask();
  const BinaryMask& mask = options_.mask_majority_filter ? filtered : raw_mask;
  if (!(options_.voxel_size > 0.0) || !(options_.hit_probability > 0.5 && options_.hit_probability < 1.0) ||
      !(options_.miss_probability > 0.0 && options_.miss_probability < 0.5) ||
      !(options_.clamp_min > 0.0 && options_.clamp_min < options_.clamp_max && options_.clamp_max < 1.0))
    throw Error(
        "voxel integration: voxel size must be positive and 0 < miss < 0.5 < hit < 1, 0 < clamp_min < clamp_max < 1");
  ++frames_;
  VoxelUpdate update;
  const float l_hit = static_cast<float>(logit(options_.hit_probability));
  const float l_miss = static_cast<float>(logit(options_.miss_probability));
  const float l_min = static_cast<float>(logit(options_.clamp_min));
  const float l_max = static_cast<float>(logit(options_.clamp_max));
  const Eigen::Matrix3d R_wc = pose.rotation().transpose();
  const Eigen::Vector3d c_w = pose.center();
  const int stride = std::max(1, options_.pixel_stride);

  // Hits: every depth pixel inside the mask (within the depth gate), back-projected; a voxel
  // is hit once per keyframe.
  const auto [gate_lo, gate_hi] = depthGate(depth, mask, stride);
  for (int ly = 0; ly < mask.height; ly += stride) {
    const int y = ly + mask.y0;
    for (int lx = 0; lx < mask.width; lx += stride) {
      if (mask.at(lx, ly) == 0) continue;
      const int x = lx + mask.x0;
      const double d = depth.at(x, y);
      if (!(d >= gate_lo && d <= gate_hi)) continue;
      const Eigen::Vector3d x_c((x - K.cx) / K.fx * d, (y - K.cy) / K.fy * d, d);
      const Eigen::Vector3d x_w = R_wc * x_c + c_w;
      const auto key = keyOf(x_w);
      if (!key) continue;
      bool added = false;
      Voxel& v = voxels_[indexOrAdd(*key, &added)];
      if (added) ++update.added;
      addToMean(v, (x_w - centreOf(*key)) / options_.voxel_size, 1);  // every point, not once per keyframe
      if (v.stamp == frames_) continue;
      v.stamp = frames_;
      v.log_odds = std::min(l_max, v.log_odds + l_hit);
      ++update.hits;
    }
  }

  // Misses: voxels not hit this keyframe that the camera should have seen as the object.
  for (size_t i = 0; i < voxels_.size(); ++i) {
    Voxel& v = voxels_[i];
    if (v.stamp == frames_) continue;
    const Eigen::Vector3d x_c = pose.transform(centreOf(keys_[i]));
    if (x_c.z() < options_.min_depth) continue;
    const int u = static_cast<int>(std::lround(K.fx * x_c.x() / x_c.z() + K.cx));
    const int w = static_cast<int>(std::lround(K.fy * x_c.y() / x_c.z() + K.cy));
    if (u < 0 || w < 0 || u >= K.width || w >= K.height) continue;
    const double d = depth.at(u, w);
    if (!(d >= options_.min_depth && d <= options_.max_depth)) continue;  // no reading: no evidence
    const bool hidden = x_c.z() > d + options_.depth_tolerance;
    const bool in_free_space = x_c.z() < d - options_.depth_tolerance;
    const bool seen_outside_mask = !inMask(mask, u, w) && !hidden;
    if (!seen_outside_mask && !in_free_space) continue;
    v.log_odds = std::max(l_min, v.log_odds + l_miss);
    ++update.misses;
  }
  enforceBudget();
  return update;
}

void VoxelObject::enforceBudget() {
  if (options_.max_voxels == 0 || voxels_.size() <= options_.max_voxels) return;
  std::vector<float> odds;
  odds.reserve(voxels_.size());
  for (const Voxel& v : voxels_) odds.push_back(v.log_odds);
  const size_t drop = voxels_.size() - options_.max_voxels;
  std::nth_element(odds.begin(), odds.begin() + static_cast<long>(drop), odds.end());
  const float cut = odds[drop];
  // Everything below the cut goes (at most `drop` voxels), then the first voxels at the cut
  // until `drop` are gone.
  size_t at_cut =
      drop - static_cast<size_t>(std::count_if(odds.begin(), odds.end(), [cut](float l) { return l < cut; }));
  keepIf([&](const Voxel& v) {
    if (v.log_odds < cut) return false;
    if (v.log_odds == cut && at_cut > 0) {
      --at_cut;
      return false;
    }
    return true;
  });
}

size_t VoxelObject::prune(double probability) {
  if (!(probability > 0.0 && probability < 1.0)) return 0;
  const float cut = static_cast<float>(logit(probability));
  return keepIf([cut](const Voxel& v) { return v.log_odds >= cut; });
}

void VoxelObject::absorb(const VoxelObject& other) {
  const float l_min = static_cast<float>(logit(options_.clamp_min));
  const float l_max = static_cast<float>(logit(options_.clamp_max));
  for (size_t i = 0; i < other.voxels_.size(); ++i) {
    const Voxel& theirs = other.voxels_[i];
    bool added = false;
    Voxel& v = voxels_[indexOrAdd(other.keys_[i], &added)];
    v.log_odds = std::clamp(v.log_odds + theirs.log_odds, l_min, l_max);
    addToMean(v, Eigen::Vector3d(theirs.mean[0], theirs.mean[1], theirs.mean[2]) / kMeanUnits, theirs.points);
    // The other model's integrations are numbered after this one's, so that each voxel still
    // moves with the keyframe that placed it (moveWithKeyframes).
    if (theirs.stamp > 0) v.stamp = frames_ + theirs.stamp;
  }
  frames_ += other.frames_;
  enforceBudget();
}

void VoxelObject::moveRigidly(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) { moveWithKeyframes({Pose(R, t)}); }

void VoxelObject::moveWithKeyframes(const std::vector<Pose>& motions) {
  if (motions.empty()) return;
  std::vector<uint64_t> old_keys;
  std::vector<Voxel> old_voxels;
  old_keys.swap(keys_);
  old_voxels.swap(voxels_);
  slots_.clear();
  for (size_t i = 0; i < old_keys.size(); ++i) {
    const Voxel& before = old_voxels[i];
    const size_t k = std::clamp<size_t>(before.stamp, 1, motions.size());
    const Eigen::Vector3d x = motions[k - 1].transform(pointMeanOf(old_keys[i], before));
    const std::optional<uint64_t> key = keyOf(x);
    if (!key) continue;
    bool added = false;
    Voxel& v = voxels_[indexOrAdd(*key, &added)];
    v.log_odds = added ? before.log_odds : std::max(v.log_odds, before.log_odds);
    v.stamp = added ? before.stamp : std::max(v.stamp, before.stamp);
    addToMean(v, (x - centreOf(*key)) / options_.voxel_size, std::max<long>(1, before.points));
  }
}

size_t VoxelObject::occupiedCount() const {
  size_t n = 0;
  for (const Voxel& v : voxels_) n += occupied(v);
  return n;
}

float VoxelObject::logOddsCut(std::optional<double> min_probability) const {
  const double p = std::clamp(min_probability.value_or(options_.occupied_probability), 1e-9, 1.0 - 1e-9);
  return static_cast<float>(logit(p));
}

Eigen::Vector3d VoxelObject::pointMeanOf(uint64_t key, const Voxel& v) const {
  return centreOf(key) + Eigen::Vector3d(v.mean[0], v.mean[1], v.mean[2]) * (options_.voxel_size / kMeanUnits);
}

template <class PointOf>
std::vector<Eigen::Vector3d> VoxelObject::pointsAtOrAbove(std::optional<double> min_probability,
                                                          PointOf point_of) const {
  const float cut = logOddsCut(min_probability);
  std::vector<Eigen::Vector3d> out;
  out.reserve(voxels_.size());
  for (size_t i = 0; i < voxels_.size(); ++i)
    if (voxels_[i].log_odds >= cut) out.push_back(point_of(keys_[i], voxels_[i]));
  return out;
}

std::vector<Eigen::Vector3d> VoxelObject::occupiedCentres(std::optional<double> min_probability) const {
  return pointsAtOrAbove(min_probability, [this](uint64_t key, const Voxel&) { return centreOf(key); });
}

std::vector<Eigen::Vector3d> VoxelObject::occupiedPointMeans(std::optional<double> min_probability) const {
  return pointsAtOrAbove(min_probability, [this](uint64_t key, const Voxel& v) { return pointMeanOf(key, v); });
}

Eigen::AlignedBox3d VoxelObject::bounds() const {
  Eigen::AlignedBox3d box;
  for (size_t i = 0; i < voxels_.size(); ++i)
    if (occupied(voxels_[i])) box.extend(centreOf(keys_[i]));
  return box;
}

std::optional<Box> VoxelObject::projectedBox(const Intrinsics& K, const Pose& pose, int min_voxels,
                                             const Ellipsoid* within, double within_scale) const {
  if (!K.isValid() || !pose.isValid()) return std::nullopt;
  double x1 = 1e300, y1 = 1e300, x2 = -1e300, y2 = -1e300;
  int n = 0;
  for (size_t i = 0; i < voxels_.size(); ++i) {
    if (!occupied(voxels_[i])) continue;
    const Eigen::Vector3d x_w = centreOf(keys_[i]);
    if (within && !(within->mahalanobisRadius(x_w) <= within_scale)) continue;
    const Eigen::Vector3d x_c = pose.transform(x_w);
    if (x_c.z() < 1e-3) continue;
    const double u = K.fx * x_c.x() / x_c.z() + K.cx, w = K.fy * x_c.y() / x_c.z() + K.cy;
    if (u < -0.5 || w < -0.5 || u > K.width - 0.5 || w > K.height - 0.5) continue;
    x1 = std::min(x1, u), x2 = std::max(x2, u), y1 = std::min(y1, w), y2 = std::max(y2, w);
    ++n;
  }
  if (n < std::max(1, min_voxels)) return std::nullopt;
  return Box(x1, y1, x2, y2);
}

long VoxelObject::countNear(const VoxelObject& other, double radius) const {
  const double size = options_.voxel_size;
  const double radius2 = radius * radius + 1e-12;  // two voxels are near: centres within the radius
  const int reach = std::max(1, static_cast<int>(std::ceil(radius / size)));
  Eigen::AlignedBox3d reach_box = other.bounds();
  if (reach_box.isEmpty()) return 0;
  reach_box.min().array() -= radius + size;
  reach_box.max().array() += radius + size;
  // The other's occupied voxels by cells of `reach` voxels a side: a voxel's neighbours within
  // the radius lie in its own cell or the 26 around it.
  const auto cellOf = [reach](const Eigen::Vector3i& g) {
    const auto floorDiv = [reach](int a) { return a >= 0 ? a / reach : -((-a + reach - 1) / reach); };
    return Eigen::Vector3i(floorDiv(g(0)), floorDiv(g(1)), floorDiv(g(2)));
  };
  std::unordered_map<uint64_t, std::vector<Eigen::Vector3i>> cells;
  for (size_t i = 0; i < other.voxels_.size(); ++i)
    if (other.occupied(other.voxels_[i])) {
      const Eigen::Vector3i g = unpack(other.keys_[i]), c = cellOf(g);
      cells[pack(c(0), c(1), c(2))].push_back(g);
    }
  const auto hasNeighbour = [&](uint64_t key) {
    if (const long same = other.indexOf(key); same >= 0 && other.occupied(other.voxels_[static_cast<size_t>(same)]))
      return true;
    const Eigen::Vector3i g = unpack(key), c = cellOf(g);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells.find(pack(c(0) + dx, c(1) + dy, c(2) + dz));
          if (it == cells.end()) continue;
          for (const Eigen::Vector3i& q : it->second)
            if (static_cast<double>((q - g).squaredNorm()) * size * size <= radius2) return true;
        }
    return false;
  };
  long n = 0;
  for (size_t i = 0; i < voxels_.size(); ++i)
    if (occupied(voxels_[i]) && reach_box.contains(centreOf(keys_[i])) && hasNeighbour(keys_[i])) ++n;
  return n;
}

double VoxelObject::probabilityAt(const Eigen::Vector3d& x_w) const {
  const auto key = keyOf(x_w);
  if (!key) return 0.5;
  const long i = indexOf(*key);
  return i < 0 ? 0.5 : 1.0 / (1.0 + std::exp(-static_cast<double>(voxels_[static_cast<size_t>(i)].log_odds)));
}

size_t VoxelObject::memoryBytes() const {
  return keys_.capacity() * sizeof(uint64_t) + voxels_.capacity() * sizeof(Voxel) +
         slots_.capacity() * sizeof(uint32_t);
}

BinaryMask maskFromBox(const Box& box, int image_width, int image_height) {
  BinaryMask m;
  m.image_width = image_width;
  m.image_height = image_height;
  if (!box.isValid()) return m;  // empty: zero-sized crop
  // Pixel (x, y) covers [x - 0.5, x + 0.5]: it belongs to the box when its centre is inside.
  // Clamped to the image before the cast: a box may lie far outside it (any finite number).
  const auto pixel = [](double v, double lo, double hi) { return static_cast<int>(std::clamp(v, lo, hi)); };
  const int x1 = pixel(std::ceil(box.x1), 0.0, image_width), y1 = pixel(std::ceil(box.y1), 0.0, image_height);
  const int x2 = pixel(std::floor(box.x2), -1.0, image_width - 1.0);
  const int y2 = pixel(std::floor(box.y2), -1.0, image_height - 1.0);
  if (x2 < x1 || y2 < y1) return m;
  m.x0 = x1;
  m.y0 = y1;
  m.width = x2 - x1 + 1;
  m.height = y2 - y1 + 1;
  m.data.assign(static_cast<size_t>(m.width) * static_cast<size_t>(m.height), 1);
  return m;
}

}  // namespace ellreloc
