// The geometry entry points fed raw floats (NaN, inf, huge, tiny): projection, distances,
// P3P. Results are a status or finite numbers, never NaN that claims to be valid.
#include <cmath>

#include "ellreloc/core.hpp"
#include "ellreloc/core/p3p.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ellreloc;
  fuzz::Input in(data, size);
  const bool raw = in.small(2) == 0;  // raw bit patterns, or values in a plausible range
  const auto num = [&](double lo, double hi) { return raw ? in.real() : in.scaled(lo, hi); };

  const Ellipse a({num(-1e3, 1e3), num(-1e3, 1e3)}, {num(0, 500), num(0, 500)}, num(-4, 4));
  const Ellipse b({num(-1e3, 1e3), num(-1e3, 1e3)}, {num(0, 500), num(0, 500)}, num(-4, 4));
  if (a.isValid() && b.isValid()) {
    const double w = wasserstein2(a, b), iou = ellipseIoU(a, b, 32), bh = bhattacharyya(a, b);
    FUZZ_CHECK(!std::isnan(w) && w >= 0.0 && iou >= -1e-9 && iou <= 1 + 1e-9 && !std::isnan(bh));
    FUZZ_CHECK(!std::isnan(levelSetDistance(a, b, 4)));
  }
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(num(-4, 4), Eigen::Vector3d(num(-1, 1), num(-1, 1), num(-1, 1)).normalized())
          .toRotationMatrix();
  const Ellipsoid q({num(-5, 5), num(-5, 5), num(-5, 5)}, {num(0, 2), num(0, 2), num(0, 2)}, R);
  const Intrinsics K(num(1, 2000), num(1, 2000), num(0, 640), num(0, 480), 640, 480);
  const Pose pose = Pose::lookAt({num(-5, 5), num(-5, 5), num(-5, 5)}, {num(-5, 5), num(-5, 5), num(-5, 5)});
  const Projection p = project(q, K, pose);
  FUZZ_CHECK(!p.ok() || p.ellipse.isValid());
  const auto conic = Ellipse::fromDualConic(q.dualQuadric().topLeftCorner<3, 3>());
  FUZZ_CHECK(!conic || conic->isValid());

  std::array<Eigen::Vector3d, 3> bearings, points;
  for (int i = 0; i < 3; ++i) {
    bearings[static_cast<size_t>(i)] = Eigen::Vector3d(num(-1, 1), num(-1, 1), num(0.1, 1)).normalized();
    points[static_cast<size_t>(i)] = Eigen::Vector3d(num(-5, 5), num(-5, 5), num(-5, 5));
  }
  std::array<Pose, 4> poses;
  const int n = p3p(bearings, points, &poses);
  FUZZ_CHECK(n >= 0 && n <= 4);
  for (int i = 0; i < n; ++i)
    FUZZ_CHECK(poses[static_cast<size_t>(i)].rotation().allFinite() &&
               poses[static_cast<size_t>(i)].translation().allFinite());
  return 0;
}
