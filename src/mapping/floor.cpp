#include "ellreloc/mapping/floor.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>
#include <vector>

namespace ellreloc {

std::optional<FloorPlane> estimateFloor(const Intrinsics& K, const Pose& pose, const DepthImage& depth,
                                        const FloorOptions& options) {
  if (!K.isValid() || !pose.isValid() || depth.width != K.width || depth.height != K.height ||
      !options.prior_up.allFinite() || !(options.prior_up.norm() > 0.0))
    return std::nullopt;
  const Eigen::Vector3d prior = options.prior_up.normalized();
  const Eigen::Matrix3d R_wc = pose.rotation().transpose();
  const Eigen::Vector3d c_w = pose.center();
  std::vector<Eigen::Vector3d> pts;
  const int stride = std::max(1, options.pixel_stride);
  for (int y = 0; y < depth.height; y += stride)
    for (int x = 0; x < depth.width; x += stride) {
      const double d = depth.at(x, y);
      if (!(d > 0.0) || !std::isfinite(d)) continue;
      pts.push_back(R_wc * Eigen::Vector3d((x - K.cx) / K.fx * d, (y - K.cy) / K.fy * d, d) + c_w);
    }
  if (pts.size() < 3) return std::nullopt;

  const double cos_tilt = std::cos(options.max_tilt_deg * M_PI / 180.0);
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<size_t> pick(0, pts.size() - 1);
  long best_count = 0;
  Eigen::Vector3d best_n = prior;
  double best_offset = 0.0;
  for (int it = 0; it < options.iterations; ++it) {
    const Eigen::Vector3d &a = pts[pick(rng)], &b = pts[pick(rng)], &c = pts[pick(rng)];
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (!(n.norm() > 1e-9)) continue;
    n.normalize();
    if (n.dot(prior) < 0.0) n = -n;
    if (n.dot(prior) < cos_tilt) continue;  // a wall or a slope, not a floor
    const double offset = n.dot(a);
    long count = 0;
    for (const Eigen::Vector3d& p : pts) count += std::abs(n.dot(p) - offset) <= options.inlier_distance;
    if (count > best_count) best_count = count, best_n = n, best_offset = offset;
  }
  if (best_count < options.min_inlier_share * static_cast<double>(pts.size()) || best_count < 3) return std::nullopt;

  // Least squares on the inliers: the normal is the direction of least spread.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  std::vector<const Eigen::Vector3d*> inliers;
  for (const Eigen::Vector3d& p : pts)
    if (std::abs(best_n.dot(p) - best_offset) <= options.inlier_distance) inliers.push_back(&p), mean += p;
  mean /= static_cast<double>(inliers.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d* p : inliers) cov += (*p - mean) * (*p - mean).transpose();
  Eigen::Vector3d n = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
  if (n.dot(prior) < 0.0) n = -n;
  if (!n.allFinite()) return std::nullopt;
  FloorPlane plane;
  plane.up = n;
  plane.offset = n.dot(mean);
  plane.inlier_share = static_cast<double>(inliers.size()) / static_cast<double>(pts.size());
  return plane;
}

}  // namespace ellreloc
