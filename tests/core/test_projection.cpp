#include "ellreloc/core/projection.hpp"

#include "fixtures/random_geometry.hpp"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include <limits>

using namespace ellreloc;
using ellreloc::test::uniform;

namespace {

/// Points of the occluding contour: on the unit sphere of the ellipsoid's normalised frame
/// they are the circle y . o = 1 (o = camera centre in that frame), mapped back to the world.
std::vector<Eigen::Vector3d> occludingContour(const Ellipsoid& e, const Eigen::Vector3d& camera_center, int n) {
  const Eigen::Vector3d o = (e.rotation().transpose() * (camera_center - e.center())).cwiseQuotient(e.axes());
  const double d2 = o.squaredNorm();
  const Eigen::Vector3d p0 = o / d2;
  const double r = std::sqrt(1.0 - 1.0 / d2);
  const Eigen::Vector3d u = o.unitOrthogonal(), v = o.normalized().cross(u);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) {
    const double t = 2.0 * M_PI * i / n;
    const Eigen::Vector3d y = p0 + r * (std::cos(t) * u + std::sin(t) * v);
    points.push_back(e.center() + e.rotation() * e.axes().cwiseProduct(y));
  }
  return points;
}

/// An ellipsoid within 2 m of the origin, semi-axes of 1 cm to 1 m (often needles or discs), any
/// rotation: in front of, behind, around and across a camera near the origin.
Ellipsoid randomPlacement(std::mt19937& rng) {
  return Ellipsoid({uniform(rng, -2, 2), uniform(rng, -2, 2), uniform(rng, -2, 2)},
                   {uniform(rng, 0.01, 1), uniform(rng, 0.01, 1), uniform(rng, 0.01, 1)},
                   ellreloc::test::randomRotation(rng));
}

}  // namespace

TEST(Projection, SurfaceProjectsInsideAndContourOnTheEllipse) {
  std::mt19937 rng(21);
  const Intrinsics K = ellreloc::test::testIntrinsics();
  int checked = 0;
  for (int i = 0; i < 300; ++i) {
    const Ellipsoid e = ellreloc::test::randomEllipsoid(rng);
    const Pose pose = ellreloc::test::randomLookAtPose(rng);
    const Projection proj = project(e, K, pose);
    ASSERT_TRUE(proj.ok()) << toString(proj.status);
    ++checked;
    double max_radius = 0.0;
    for (const auto& x : e.sampleSurface(500)) {
      const double r = proj.ellipse.mahalanobisRadius(K.project(pose.transform(x)));
      EXPECT_LE(r, 1.0 + 1e-9);
      max_radius = std::max(max_radius, r);
    }
    EXPECT_GT(max_radius, 0.95);  // the projection is tight, not just an enclosing ellipse
    for (const auto& x : occludingContour(e, pose.center(), 24)) {
      EXPECT_NEAR(proj.ellipse.mahalanobisRadius(K.project(pose.transform(x))), 1.0, 1e-8);
    }
  }
  EXPECT_EQ(checked, 300);
}

TEST(Projection, AgreesWithOpenCvProjectPoints) {
  std::mt19937 rng(22);
  const Intrinsics K = ellreloc::test::testIntrinsics();
  cv::Mat cvK;
  cv::eigen2cv(K.K(), cvK);
  for (int i = 0; i < 200; ++i) {
    const Ellipsoid e = ellreloc::test::randomEllipsoid(rng);
    const Pose pose = ellreloc::test::randomLookAtPose(rng);
    const Projection proj = project(e, K, pose);
    ASSERT_TRUE(proj.ok());
    std::vector<cv::Point3d> object;
    for (const auto& x : occludingContour(e, pose.center(), 36)) object.emplace_back(x(0), x(1), x(2));
    cv::Mat R, rvec, tvec;
    cv::eigen2cv(pose.rotation(), R);
    cv::Rodrigues(R, rvec);
    cv::eigen2cv(pose.translation(), tvec);
    std::vector<cv::Point2d> image;
    cv::projectPoints(object, rvec, tvec, cvK, cv::noArray(), image);
    // The contour's image is the ellipse: fit a conic through it with OpenCV's own points and
    // compare through the boundary equation, and compare the bounding boxes.
    double x1 = 1e18, y1 = 1e18, x2 = -1e18, y2 = -1e18;
    for (const auto& p : image) {
      EXPECT_NEAR(proj.ellipse.mahalanobisRadius({p.x, p.y}), 1.0, 1e-7);
      x1 = std::min(x1, p.x), y1 = std::min(y1, p.y), x2 = std::max(x2, p.x), y2 = std::max(y2, p.y);
    }
    const Box b = proj.ellipse.boundingBox();
    EXPECT_LE(b.x1, x1 + 1e-6);
    EXPECT_GE(b.x2, x2 - 1e-6);
    EXPECT_LE(b.y1, y1 + 1e-6);
    EXPECT_GE(b.y2, y2 - 1e-6);
  }
}

TEST(Projection, FailuresAreStatusesNotNaN) {
  const Intrinsics K = ellreloc::test::testIntrinsics();
  const Pose identity;  // camera at the origin looking along +z
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const double nan = std::numeric_limits<double>::quiet_NaN();

  EXPECT_TRUE(project(Ellipsoid({0, 0, 3}, {0.2, 0.3, 0.4}, I), K, identity).ok());
  EXPECT_EQ(project(Ellipsoid({0, 0, -3}, {0.2, 0.3, 0.4}, I), K, identity).status, ProjectionStatus::BehindCamera);
  EXPECT_EQ(project(Ellipsoid({0, 0, 0.1}, {0.5, 0.5, 0.5}, I), K, identity).status, ProjectionStatus::ContainsCamera);
  EXPECT_EQ(project(Ellipsoid({1, 0, 0.1}, {0.2, 0.2, 0.2}, I), K, identity).status, ProjectionStatus::NotAnEllipse);
  EXPECT_EQ(project(Ellipsoid({0, 0, 3}, {0.2, 0.0, 0.4}, I), K, identity).status, ProjectionStatus::InvalidInput);
  EXPECT_EQ(project(Ellipsoid({0, 0, 3}, {0.2, -1.0, 0.4}, I), K, identity).status, ProjectionStatus::InvalidInput);
  EXPECT_EQ(project(Ellipsoid({0, 0, 3}, {0.2, nan, 0.4}, I), K, identity).status, ProjectionStatus::InvalidInput);
  EXPECT_EQ(project(Ellipsoid({0, 0, 3}, {0.2, 0.3, std::numeric_limits<double>::infinity()}, I), K, identity).status,
            ProjectionStatus::InvalidInput);
  EXPECT_EQ(project(Ellipsoid({0, 0, 3}, {0.2, 0.3, 0.4}, I), K, Pose(I, {nan, 0, 0})).status,
            ProjectionStatus::InvalidInput);
  EXPECT_EQ(project(Ellipsoid({0, 0, 3}, {0.2, 0.3, 0.4}, I), Intrinsics(0, 500, 320, 240, 640, 480), identity).status,
            ProjectionStatus::InvalidInput);

  // Random placements around a camera in random poses: every result is either a valid ellipse
  // or a status, and an ellipse exactly when the support function puts the whole ellipsoid in
  // front of the camera (the projection tests it by the sign of C*_33 instead).
  std::mt19937 rng(23);
  int ok = 0, failed = 0;
  for (int i = 0; i < 2000; ++i) {
    const Ellipsoid e = randomPlacement(rng);
    const Eigen::Vector3d t(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    const Pose pose(ellreloc::test::randomRotation(rng), t);
    const Projection p = project(e, K, pose);
    double near = 0.0, far = 0.0;
    depthRange<double>(pose.rotation(), pose.translation(), e.center(), e.shapeMatrix(), &near, &far);
    EXPECT_EQ(p.ok(), near > 0.0) << toString(p.status) << ", nearest depth " << near;
    if (p.ok()) {
      EXPECT_TRUE(p.ellipse.isValid());
      // In front of the camera: every surface point has positive depth.
      for (const auto& x : e.sampleSurface(50)) EXPECT_GT(pose.transform(x)(2), 0.0);
      ++ok;
    } else {
      EXPECT_EQ(p.status, e.contains(pose.center()) ? ProjectionStatus::ContainsCamera
                          : far <= 0.0             ? ProjectionStatus::BehindCamera
                                                   : ProjectionStatus::NotAnEllipse);
      ++failed;
    }
  }
  EXPECT_GT(ok, 100);
  EXPECT_GT(failed, 100);
}

TEST(Projection, ImageAreaBoundsHoldAtRandomPoses) {
  const Intrinsics K = ellreloc::test::testIntrinsics();
  std::mt19937 rng(25);
  int ok = 0, failed = 0, lower_useful = 0, upper_useful = 0;
  for (int i = 0; i < 4000; ++i) {
    const Ellipsoid e = randomPlacement(rng);
    const Pose pose(ellreloc::test::randomRotation(rng), {uniform(rng, -1, 1), uniform(rng, -1, 1), 0.0});
    const Projection p = project(e, K, pose);
    const ImageAreaBounds b = imageAreaBounds(ProjectableEllipsoid(e), K, pose);
    if (!p.ok()) {
      ++failed;
      continue;
    }
    ++ok;
    const double area = p.ellipse.area();
    EXPECT_LE(b.lower, area * (1 + 1e-9)) << "placement " << i;
    EXPECT_GE(b.upper, area * (1 - 1e-9)) << "placement " << i;
    lower_useful += b.lower > 0.25 * area;
    upper_useful += b.upper < 4.0 * area;
  }
  EXPECT_GT(ok, 500);
  EXPECT_GT(failed, 500);
  // Not vacuous: for many placements (random axes 0.01-1 m, often needles or discs) each bound
  // is within a factor 4 of the area.
  EXPECT_GT(lower_useful, ok / 3);
  EXPECT_GT(upper_useful, ok / 3);
}

TEST(Projection, ImageAreaBoundsAreExactForSpheresAndCloseForDiscsFacingTheCamera) {
  const Intrinsics K = ellreloc::test::testIntrinsics();
  const Pose identity;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (const Eigen::Vector3d c : {Eigen::Vector3d(0, 0, 3), Eigen::Vector3d(1.5, -1, 2.5), Eigen::Vector3d(-2, 0, 2)}) {
    const Ellipsoid sphere(c, {0.3, 0.3, 0.3}, I);
    const double area = project(sphere, K, identity).ellipse.area();
    const ImageAreaBounds b = imageAreaBounds(ProjectableEllipsoid(sphere), K, identity);
    EXPECT_NEAR(b.lower, area, 1e-9 * area);
    EXPECT_NEAR(b.upper, area, 1e-9 * area);
  }
  // A disc 2 mm thick facing the camera: the sphere of its smallest axis says nothing, its
  // section nearly everything (within (D / sqrt(D^2 + r^2))^3 = 0.985 of the area).
  const Ellipsoid disc({0, 0, 3}, {0.3, 0.2, 0.002}, I);
  const double area = project(disc, K, identity).ellipse.area();
  EXPECT_GT(imageAreaBounds(ProjectableEllipsoid(disc), K, identity).lower, 0.98 * area);
  // Where no image is an ellipse, the lower bound is infinite.
  EXPECT_EQ(imageAreaBounds(ProjectableEllipsoid(Ellipsoid({0, 0, 0.1}, {0.2, 0.2, 0.2}, I)), K, identity).lower,
            INFINITY);
}

TEST(Projection, CentreAloneIsTheCentreOfTheWholeProjection) {
  // Random placements around the camera, in front, behind, around and across it.
  const Intrinsics K = ellreloc::test::testIntrinsics();
  const Pose identity;
  std::mt19937 rng(24);
  int ok = 0, failed = 0;
  for (int i = 0; i < 2000; ++i) {
    const Ellipsoid e = randomPlacement(rng);
    const Projection whole = project(e, K, identity);
    const std::optional<Eigen::Vector2d> centre =
        projectedCentre(ProjectableEllipsoid(e), projectionMatrix(K, identity));
    ASSERT_EQ(centre.has_value(), whole.ok()) << toString(whole.status);
    if (!whole.ok()) {
      ++failed;
      continue;
    }
    ++ok;
    EXPECT_LT((*centre - whole.ellipse.center()).norm(), 1e-9 * (1.0 + whole.ellipse.center().norm()));
  }
  EXPECT_GT(ok, 100);
  EXPECT_GT(failed, 100);
}
