// The smallest useful program: a built-in scene of six objects, the image ellipses a camera
// sees of them, and how the Wasserstein distance between observation and projection grows
// as the camera pose is perturbed (what the relocalizer's refinement minimises).
#include <ellreloc/core.hpp>

#include <cstdio>

int main() {
  using namespace ellreloc;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const auto yaw = [](double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); };
  // Objects on a 0.75 m table (world z up): monitor, keyboard, cup, book, bottle, chair.
  const Ellipsoid scene[] = {
      {{0.0, 0.3, 1.0}, {0.28, 0.04, 0.2}, yaw(0.1)},  {{0.0, 0.0, 0.77}, {0.22, 0.07, 0.015}, yaw(-0.05)},
      {{0.35, 0.05, 0.8}, {0.04, 0.04, 0.05}, I},      {{-0.4, 0.1, 0.77}, {0.12, 0.09, 0.02}, yaw(0.6)},
      {{0.5, 0.35, 0.86}, {0.035, 0.035, 0.11}, I},    {{0.1, -0.6, 0.45}, {0.25, 0.25, 0.45}, yaw(0.3)}};
  // A camera 1.5 m in front of the table at eye height, looking at it.
  Eigen::Matrix3d R_wc;
  R_wc.col(2) = Eigen::Vector3d(0.0, 1.4, -0.6).normalized();                   // optical axis
  R_wc.col(0) = R_wc.col(2).cross(Eigen::Vector3d::UnitZ()).normalized();       // image x
  R_wc.col(1) = R_wc.col(2).cross(R_wc.col(0));                                 // image y (down)
  const Pose truth = Pose::fromCameraToWorld(R_wc, {0.0, -1.5, 1.4});
  const Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);

  std::printf("object  centre (px)        semi-axes (px)   angle (deg)\n");
  std::vector<std::pair<const Ellipsoid*, Ellipse>> observed;  // (object, its image)
  for (const Ellipsoid& e : scene) {
    const Projection p = project(e, K, truth);
    if (!p) {
      std::printf("  not visible: %s\n", toString(p.status));
      continue;
    }
    observed.emplace_back(&e, p.ellipse);
    const Ellipse& el = p.ellipse;
    std::printf("%4zu   (%6.1f, %6.1f)   (%5.1f, %5.1f)   %6.1f\n", observed.size() - 1, el.center()(0), el.center()(1),
                el.axes()(0), el.axes()(1), el.angle() * 180.0 / M_PI);
  }
  std::printf("\nrotation error -> mean W2 between observations and projections (px)\n");
  for (double deg : {0.0, 0.5, 1.0, 2.0, 5.0}) {
    const Pose moved(Eigen::AngleAxisd(deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix() * truth.rotation(),
                     truth.translation());
    double sum = 0.0;
    for (const auto& [object, image] : observed) {
      const Projection p = project(*object, K, moved);
      sum += p ? wasserstein2(image, p.ellipse) : 1e3;  // a lost object costs a large constant
    }
    std::printf("  %4.1f deg -> %7.2f\n", deg, sum / observed.size());
  }
  return 0;
}
