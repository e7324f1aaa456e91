#include "ellreloc/sim/render.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ellreloc::sim {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNear = 0.05;  // metres: nearer surfaces are not rendered

}  // namespace

namespace {

/// Ray depth in the primitive's own frame (o, d local; t keeps its meaning under rotation).
double localRayDepth(const Primitive& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const Eigen::Vector3d& h = p.half;
  if (p.shape == PrimitiveShape::Box) {
    double t_near = -kInf, t_far = kInf;
    for (int i = 0; i < 3; ++i) {
      if (std::abs(d(i)) < 1e-15) {
        if (std::abs(o(i)) > h(i)) return kInf;
        continue;
      }
      double t1 = (-h(i) - o(i)) / d(i), t2 = (h(i) - o(i)) / d(i);
      if (t1 > t2) std::swap(t1, t2);
      t_near = std::max(t_near, t1);
      t_far = std::min(t_far, t2);
    }
    return t_near <= t_far && t_near > kNear ? t_near : kInf;
  }
  if (p.shape == PrimitiveShape::Ellipsoid) {  // unit sphere after scaling by the semi-axes
    const Eigen::Vector3d os = o.cwiseQuotient(h), ds = d.cwiseQuotient(h);
    const double a = ds.squaredNorm(), b = 2.0 * os.dot(ds), c = os.squaredNorm() - 1.0;
    const double disc = b * b - 4 * a * c;
    if (disc < 0 || a <= 0) return kInf;
    const double t = (-b - std::sqrt(disc)) / (2 * a);
    return t > kNear ? t : kInf;
  }
  // Cylinder of radius h(0), axis local z, |z| <= h(2): side and caps.
  double best = kInf;
  const double a = d(0) * d(0) + d(1) * d(1);
  if (a > 1e-15) {
    const double b = 2.0 * (o(0) * d(0) + o(1) * d(1)), c = o(0) * o(0) + o(1) * o(1) - h(0) * h(0);
    const double disc = b * b - 4 * a * c;
    if (disc >= 0) {
      const double t = (-b - std::sqrt(disc)) / (2 * a);
      if (t > kNear && std::abs(o(2) + t * d(2)) <= h(2)) best = t;
    }
  }
  if (std::abs(d(2)) > 1e-15) {
    for (double zc : {-h(2), h(2)}) {
      const double t = (zc - o(2)) / d(2);
      const double x = o(0) + t * d(0), y = o(1) + t * d(1);
      if (t > kNear && x * x + y * y <= h(0) * h(0)) best = std::min(best, t);
    }
  }
  return best;
}

}  // namespace

double rayDepth(const Primitive& p, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
  return localRayDepth(p, p.rotation.transpose() * (origin - p.center), p.rotation.transpose() * direction);
}

namespace {

/// Pixel bounds of a primitive's image (its bounding box corners projected); the whole image
/// when a corner is behind the camera.
void screenBounds(const Primitive& p, const Intrinsics& K, const Pose& pose, int* x0, int* y0, int* x1, int* y1) {
  double u0 = kInf, v0 = kInf, u1 = -kInf, v1 = -kInf;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d corner =
        p.center + p.rotation * Eigen::Vector3d((k & 1 ? 1 : -1) * p.half(0), (k & 2 ? 1 : -1) * p.half(1),
                                                (k & 4 ? 1 : -1) * p.half(2));
    const Eigen::Vector3d xc = pose.transform(corner);
    if (xc(2) < kNear) {
      *x0 = 0, *y0 = 0, *x1 = K.width - 1, *y1 = K.height - 1;
      return;
    }
    const Eigen::Vector2d uv = K.project(xc);
    u0 = std::min(u0, uv(0)), v0 = std::min(v0, uv(1)), u1 = std::max(u1, uv(0)), v1 = std::max(v1, uv(1));
  }
  *x0 = std::max(0, static_cast<int>(std::floor(u0)));
  *y0 = std::max(0, static_cast<int>(std::floor(v0)));
  *x1 = std::min(K.width - 1, static_cast<int>(std::ceil(u1)));
  *y1 = std::min(K.height - 1, static_cast<int>(std::ceil(v1)));
}

}  // namespace

RenderedFrame render(const Scene& scene, const Intrinsics& K, const Pose& pose) {
  RenderedFrame f;
  f.width = K.width;
  f.height = K.height;
  const size_t n = static_cast<size_t>(K.width) * K.height;
  // The depth image doubles as the z-buffer (+inf = nothing yet; 0 at the end).
  f.depth.assign(n, std::numeric_limits<float>::infinity());
  std::vector<float>& zbuf = f.depth;
  f.instance.assign(n, kNoObject);
  // A column-major copy for the run-length pass (RLE runs go down the columns).
  std::vector<int16_t> instance_cm(n, kNoObject);
  const Eigen::Matrix3d R_wc = pose.rotation().transpose();
  const Eigen::Vector3d origin = pose.center();
  // World ray through pixel (x, y), scaled so its camera z is 1 (t = depth): linear in x, y.
  const Eigen::Vector3d d0 = R_wc * Eigen::Vector3d(-K.cx / K.fx, -K.cy / K.fy, 1.0);
  const Eigen::Vector3d dx = R_wc.col(0) / K.fx, dy = R_wc.col(1) / K.fy;
  // Floor (z = 0).
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x) {
      const double dz = d0(2) + x * dx(2) + y * dy(2);
      if (dz < -1e-12) {
        const double t = -origin(2) / dz;
        if (t > kNear) zbuf[static_cast<size_t>(y) * K.width + x] = static_cast<float>(t);
      }
    }
  auto draw = [&](const Primitive& p, int16_t id) {
    int x0, y0, x1, y1;
    screenBounds(p, K, pose, &x0, &y0, &x1, &y1);
    const Eigen::Matrix3d Rt = p.rotation.transpose();
    const Eigen::Vector3d o = Rt * (origin - p.center), l0 = Rt * d0, lx = Rt * dx, ly = Rt * dy;
    for (int y = y0; y <= y1; ++y) {
      const Eigen::Vector3d row = l0 + y * ly;
      for (int x = x0; x <= x1; ++x) {
        const double t = localRayDepth(p, o, row + x * lx);
        const size_t i = static_cast<size_t>(y) * K.width + x;
        if (t < zbuf[i]) {
          zbuf[i] = static_cast<float>(t);
          f.instance[i] = id;
          instance_cm[static_cast<size_t>(x) * K.height + y] = id;
        }
      }
    }
  };
  for (const Primitive& p : scene.furniture) draw(p, kNoObject);
  for (size_t j = 0; j < scene.objects.size(); ++j)
    for (const Primitive& p : scene.objects[j].parts) draw(p, static_cast<int16_t>(j));
  for (float& z : f.depth)
    if (!std::isfinite(z)) z = 0.0f;

  // All instance masks in one column-major pass: a run ends where the instance changes.
  const size_t m = scene.objects.size();
  f.masks.assign(m, RleMask{K.height, K.width, {}});
  f.visible_pixels.assign(m, 0);
  std::vector<uint64_t> run_start(m, 0);  // where the object's current run (of 0s or 1s) began
  std::vector<double> bx0(m, kInf), by0(m, kInf), bx1(m, -kInf), by1(m, -kInf);
  int prev = kNoObject;
  uint64_t k = 0;
  for (int x = 0; x < K.width; ++x)
    for (int y = 0; y < K.height; ++y, ++k) {
      const int id = instance_cm[k];
      if (id != prev) {
        if (prev != kNoObject) {  // prev's run of ones ends here
          f.masks[prev].counts.push_back(static_cast<uint32_t>(k - run_start[prev]));
          run_start[prev] = k;
        }
        if (id != kNoObject) {  // id's run of zeros ends here
          f.masks[id].counts.push_back(static_cast<uint32_t>(k - run_start[id]));
          run_start[id] = k;
        }
        prev = id;
      }
      if (id != kNoObject) {
        ++f.visible_pixels[id];
        bx0[id] = std::min<double>(bx0[id], x), bx1[id] = std::max<double>(bx1[id], x);
        by0[id] = std::min<double>(by0[id], y), by1[id] = std::max<double>(by1[id], y);
      }
    }
  f.boxes.assign(m, Box(0, 0, -1, -1));  // invalid until seen
  for (size_t j = 0; j < m; ++j) {
    // Close the last run: ones if the last pixel was this object's, then the trailing zeros.
    f.masks[j].counts.push_back(static_cast<uint32_t>(k - run_start[j]));  // ones or trailing zeros
    if (f.visible_pixels[j] > 0) f.boxes[j] = Box(bx0[j] - 0.5, by0[j] - 0.5, bx1[j] + 0.5, by1[j] + 0.5);
  }
  return f;
}

}  // namespace ellreloc::sim
