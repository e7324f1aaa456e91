#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <optional>
#include <random>

#include "ellreloc/core/projection.hpp"
#include "ellreloc/core/statistics.hpp"
#include "ellreloc/mapping/box_ellipsoid_builder.hpp"
#include "ellreloc/mapping/category_sizes.hpp"
#include "ellreloc/mapping/ellipsoid_builder.hpp"

namespace ellreloc {
namespace {

/// Points on the five visible faces (no bottom) of a cuboid, plus a few far outliers.
std::vector<Eigen::Vector3d> cuboidSurface(const Cuboid& c, int per_face, int outliers, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> pts;
  for (int face = 0; face < 5; ++face) {
    const int axis = face / 2, sign = face % 2 ? 1 : -1;
    const int ax = face == 4 ? 2 : axis;
    for (int i = 0; i < per_face; ++i) {
      Eigen::Vector3d s(u(rng), u(rng), u(rng));
      s(ax) = face == 4 ? 1.0 : sign;
      pts.push_back(c.center + c.rotation * s.cwiseProduct(c.half));
    }
  }
  for (int i = 0; i < outliers; ++i) pts.push_back(c.center + Eigen::Vector3d(u(rng), u(rng), u(rng)) * 3.0);
  return pts;
}

double axisAngleModPiDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) * 180.0 / M_PI;
}

TEST(EllipsoidBuilder, RecoversYawCentreAndExtentsOfACuboid) {
  std::mt19937 rng(3);
  for (const Eigen::Vector3d& up : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.2, -0.1, 1.0).normalized()}) {
    for (double yaw : {0.3, 1.2, -2.0}) {
      Cuboid truth;
      const Eigen::Matrix3d B = groundBasis(up);
      truth.rotation = B * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      truth.half = Eigen::Vector3d(0.4, 0.15, 0.25);
      truth.center = Eigen::Vector3d(1.0, -0.5, 0.25);
      EllipsoidBuilderOptions opt;
      opt.up = up;
      const auto built = buildEllipsoid(cuboidSurface(truth, 2000, 10, rng), opt);
      ASSERT_TRUE(built);
      EXPECT_LT(axisAngleModPiDeg(built->cuboid.rotation.col(0), truth.rotation.col(0)), 1.0) << yaw;
      EXPECT_LT(axisAngleModPiDeg(built->cuboid.rotation.col(2), up), 1e-9);
      EXPECT_LT((built->cuboid.center - truth.center).norm(), 0.01);
      EXPECT_NEAR(built->cuboid.half(0), 0.4, 0.01);
      EXPECT_NEAR(built->cuboid.half(1), 0.15, 0.01);
      EXPECT_NEAR(built->cuboid.half(2), 0.25, 0.01);
      EXPECT_TRUE(isRotation(built->cuboid.rotation));
      // The ellipsoid is the inscribed one: it touches the cuboid's face centres.
      const Ellipsoid& e = built->ellipsoid;
      const Eigen::Vector3d face = built->cuboid.center + built->cuboid.rotation.col(0) * built->cuboid.half(0);
      const Eigen::Vector3d d = e.rotation().transpose() * (face - e.center());
      EXPECT_NEAR(d.cwiseQuotient(e.axes()).norm(), 1.0, 1e-9);
      const auto corners = built->cuboid.corners();
      for (const auto& corner : corners)
        EXPECT_NEAR((built->cuboid.rotation.transpose() * (corner - built->cuboid.center))
                        .cwiseAbs()
                        .cwiseQuotient(built->cuboid.half)
                        .sum(),
                    3.0, 1e-9);
    }
  }
}

TEST(EllipsoidBuilder, RefusesTooFewPointsAndABadUpVector) {
  std::vector<Eigen::Vector3d> few(5, Eigen::Vector3d::Zero());
  EXPECT_FALSE(buildEllipsoid(few));
  std::vector<Eigen::Vector3d> flat;
  for (int i = 0; i < 50; ++i) flat.emplace_back(0.01 * i, 0.0, 0.0);  // a line: no width
  EXPECT_FALSE(buildEllipsoid(flat));
  std::mt19937 rng(1);
  Cuboid c;
  c.half = Eigen::Vector3d(0.2, 0.1, 0.1);
  EllipsoidBuilderOptions opt;
  opt.up = Eigen::Vector3d::Zero();
  EXPECT_FALSE(buildEllipsoid(cuboidSurface(c, 50, 0, rng), opt));
  opt.up = Eigen::Vector3d(std::nan(""), 0, 1);
  EXPECT_FALSE(buildEllipsoid(cuboidSurface(c, 50, 0, rng), opt));
}

const Intrinsics kK(525.0, 525.0, 319.5, 239.5, 640, 480);

/// The bounding box of an ellipsoid's image, if it has one.
std::optional<Box> imageBox(const Ellipsoid& e, const Pose& pose) {
  const Projection p = project(e, kK, pose);
  if (!p) return std::nullopt;
  const Eigen::Matrix2d S = p.ellipse.covariance();
  const Eigen::Vector2d h(std::sqrt(S(0, 0)), std::sqrt(S(1, 1)));
  return Box(p.ellipse.center().x() - h.x(), p.ellipse.center().y() - h.y(), p.ellipse.center().x() + h.x(),
             p.ellipse.center().y() + h.y());
}

/// Views of an ellipsoid from a ring of cameras, with the bounding boxes of its projections.
std::vector<BoxView> ringViews(const Ellipsoid& e, int n, double radius, double spread_deg) {
  std::vector<BoxView> views;
  for (int i = 0; i < n; ++i) {
    const double a = (spread_deg * M_PI / 180.0) * (static_cast<double>(i) / std::max(1, n - 1) - 0.5);
    const Eigen::Vector3d eye = e.center() + Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a), 0.6);
    const Pose pose = Pose::lookAt(eye, e.center());
    if (const std::optional<Box> box = imageBox(e, pose)) views.push_back({pose, *box});
  }
  return views;
}

TEST(BoxEllipsoidBuilder, RecoversAnEllipsoidFromItsBoxes) {
  const Ellipsoid truth(Eigen::Vector3d(0.5, 1.0, 0.4), Eigen::Vector3d(0.3, 0.15, 0.2),
                        Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix());
  const std::vector<BoxView> views = ringViews(truth, 10, 2.0, 120.0);
  const auto centre = triangulateBoxCentres(kK, views);
  ASSERT_TRUE(centre);
  EXPECT_LT((*centre - truth.center()).norm(), 0.05);  // box centres are near, not at, the centre's image
  const BoxEllipsoidResult r = buildEllipsoidFromBoxes(kK, views);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_LT((r.ellipsoid.center() - truth.center()).norm(), 0.02);
  // A box is not the inscribed ellipse's image, so even clean views leave residuals near the
  // robust loss's scale: the size prior then weighs a little more than under a wide loss.
  EXPECT_GT(r.median_iou, 0.85);
  EXPECT_NEAR(r.ellipsoid.volume(), truth.volume(), 0.25 * truth.volume());
  EXPECT_EQ(r.views_used, 10);
  EXPECT_GT(r.baseline_deg, 100.0);
  EXPECT_FALSE(r.depth_from_size);  // triangulated
  BoxEllipsoidOptions wide;
  wide.loss_scale = 1.0;
  const BoxEllipsoidResult w = buildEllipsoidFromBoxes(kK, views, wide);
  ASSERT_TRUE(w.ok()) << w.reason;
  EXPECT_GT(w.median_iou, 0.9);
}

// Three of twelve boxes belong to another object of the label 25 cm away (a tracker that took
// the neighbour's box for a few frames). The Cauchy loss lets the nine that agree decide; a
// loss nearly quadratic at this scale lets the three pull the centre.
TEST(BoxEllipsoidBuilder, BoxesOfANeighbourDoNotPullTheFit) {
  const Ellipsoid truth(Eigen::Vector3d(0.5, 1.0, 0.4), Eigen::Vector3d(0.12, 0.1, 0.08), Eigen::Matrix3d::Identity());
  const Ellipsoid neighbour(truth.center() + Eigen::Vector3d(0.0, 0.25, 0.0), truth.axes(), truth.rotation());
  std::vector<BoxView> views = ringViews(truth, 12, 1.5, 100.0);
  ASSERT_EQ(views.size(), 12u);
  for (size_t i : {2u, 6u, 10u}) {
    const std::optional<Box> other = imageBox(neighbour, views[i].pose);
    ASSERT_TRUE(other);
    views[i].box = *other;
  }
  const BoxEllipsoidResult robust = buildEllipsoidFromBoxes(kK, views);
  BoxEllipsoidOptions wide;
  wide.loss_scale = 100.0;
  const BoxEllipsoidResult pulled = buildEllipsoidFromBoxes(kK, views, wide);
  ASSERT_TRUE(robust.ok()) << robust.reason;
  ASSERT_TRUE(pulled.ok()) << pulled.reason;
  const double robust_error = (robust.ellipsoid.center() - truth.center()).norm();
  const double pulled_error = (pulled.ellipsoid.center() - truth.center()).norm();
  EXPECT_LT(robust_error, 0.02);
  EXPECT_GT(pulled_error, 2.0 * robust_error) << robust_error << " " << pulled_error;
}

// Rays that barely diverge (a camera that slid 4 cm) leave the depth to the size prior: the
// object stands on the rays where its category's typical size fills the boxes, as far away as
// that size says (the boxes fix only the ratio of size to depth; which sides they show decides
// the rest, hence the loose bound on the depth itself).
TEST(BoxEllipsoidBuilder, ANarrowBaselinePlacesTheObjectByItsTypicalSize) {
  const Ellipsoid truth(Eigen::Vector3d(0.5, 1.0, 0.4), Eigen::Vector3d(0.3, 0.15, 0.2), Eigen::Matrix3d::Identity());
  const std::vector<BoxView> views = ringViews(truth, 5, 2.0, 1.0);
  const Eigen::Vector3d eye = views[2].pose.center();
  const Eigen::Vector3d ray = (truth.center() - eye).normalized();
  const double distance = (truth.center() - eye).norm();
  double depth[2] = {0.0, 0.0};
  for (int k = 0; k < 2; ++k) {
    BoxSizePrior prior;
    prior.typical_semi_axes = (k + 1.0) * truth.axes();
    const BoxEllipsoidResult r = buildEllipsoidFromBoxes(kK, views, {}, prior);
    ASSERT_TRUE(r.ok()) << r.reason;
    EXPECT_LT(r.baseline_deg, 5.0);
    EXPECT_TRUE(r.depth_from_size);
    EXPECT_GT(r.median_iou, 0.8);
    const Eigen::Vector3d found = r.ellipsoid.center() - eye;
    depth[k] = found.dot(ray);
    EXPECT_LT((found - depth[k] * ray).norm(), 0.05 * depth[k]);  // on the rays
  }
  EXPECT_NEAR(depth[0], distance, 0.35 * distance);
  EXPECT_NEAR(depth[1] / depth[0], 2.0, 0.2);
}

/// The best IoU of `truth` with any of `boxes` (0 for none).
double bestIoU(const std::vector<Box>& boxes, const Box& truth) {
  double best = 0.0;
  for (const Box& b : boxes) best = std::max(best, boxIoU(b, truth));
  return best;
}

// Where a young object's next box should be (2D tracking between keyframes far apart): its last
// box when the camera has not moved; moved with the camera by the nearest point of rays that
// diverge; and, seen once, at the depth its category's typical size gives or up to four times
// nearer or farther, so that an object of another size than its category's is still found
// where the camera's move puts it, which the last box left in place is not.
TEST(BoxEllipsoidBuilder, PredictedBoxesFollowTheCamera) {
  // A camera sliding 10 cm at a time past a cup 1.6 m away, looking the same way: the cup's
  // image moves by more than its width from one keyframe to the next.
  const Ellipsoid cup(Eigen::Vector3d(0.0, 0.0, 0.4), Eigen::Vector3d(0.04, 0.04, 0.05), Eigen::Matrix3d::Identity());
  std::vector<BoxView> slide;
  for (int i = 0; i < 5; ++i) {
    const Eigen::Vector3d eye(-0.2 + 0.1 * i, -1.5, 0.9);
    const Pose pose = Pose::lookAt(eye, eye + Eigen::Vector3d(0.0, 1.5, -0.5));
    const std::optional<Box> box = imageBox(cup, pose);
    ASSERT_TRUE(box);
    slide.push_back({pose, *box});
  }
  EXPECT_LT(boxIoU(slide[2].box, slide[3].box), 0.1);  // the last box left in place misses it
  BoxSizePrior typical;
  typical.typical_semi_axes = cup.axes();
  const std::vector<BoxView> first(slide.begin(), slide.begin() + 1);
  const std::vector<Box> unmoved = predictedBoxes(kK, first, typical, 5.0, slide[0].pose);
  ASSERT_EQ(unmoved.size(), 9u);  // placed by its typical size: nine depths
  EXPECT_NEAR(boxIoU(unmoved.front(), slide[0].box), 1.0, 1e-9);

  // Seen three times over 7 degrees of rays: triangulated, one box, where the cup's image is next.
  const std::vector<BoxView> three(slide.begin(), slide.begin() + 3);
  const std::vector<Box> next = predictedBoxes(kK, three, typical, 5.0, slide[3].pose);
  ASSERT_EQ(next.size(), 1u);
  EXPECT_GT(boxIoU(next.front(), slide[3].box), 0.85);

  // Seen once, a cup twice its category's size: the typical depth puts it twice too far, where
  // the camera's slide moves it half as much; one of the other depths finds it.
  BoxSizePrior half;
  half.typical_semi_axes = 0.5 * cup.axes();
  const std::vector<Box> far = predictedBoxes(kK, first, half, 5.0, slide[2].pose);
  ASSERT_EQ(far.size(), 9u);
  EXPECT_LT(boxIoU(far.front(), slide[2].box), 0.3);
  EXPECT_GT(bestIoU(far, slide[2].box), 0.8);

  EXPECT_TRUE(predictedBoxes(kK, {}, typical, 5.0, slide[0].pose).empty());
  const Pose away = Pose::lookAt(Eigen::Vector3d(0.0, -1.5, 0.9), Eigen::Vector3d(0.0, -3.0, 0.9));
  EXPECT_TRUE(predictedBoxes(kK, three, typical, 5.0, away).empty());  // the cup is behind that camera
}

TEST(BoxEllipsoidBuilder, StatusesInsteadOfGuesses) {
  const Ellipsoid truth(Eigen::Vector3d(0.5, 1.0, 0.4), Eigen::Vector3d(0.3, 0.15, 0.2), Eigen::Matrix3d::Identity());
  EXPECT_EQ(buildEllipsoidFromBoxes(kK, ringViews(truth, 2, 2.0, 60.0)).status, BoxEllipsoidStatus::TooFewViews);
  BoxEllipsoidOptions no_prior;
  no_prior.use_size_prior = false;  // with it, a narrow baseline still gives an object (above)
  EXPECT_EQ(buildEllipsoidFromBoxes(kK, ringViews(truth, 5, 2.0, 1.0), no_prior).status,
            BoxEllipsoidStatus::NoBaseline);
  EXPECT_EQ(buildEllipsoidFromBoxes(Intrinsics(), ringViews(truth, 5, 2.0, 60.0)).status,
            BoxEllipsoidStatus::InvalidInput);
  BoxEllipsoidOptions no_scale;
  no_scale.loss_scale = 0.0;  // a Cauchy loss needs a positive scale
  const BoxEllipsoidResult unscaled = buildEllipsoidFromBoxes(kK, ringViews(truth, 5, 2.0, 60.0), no_scale);
  EXPECT_EQ(unscaled.status, BoxEllipsoidStatus::InvalidInput);
  EXPECT_EQ(unscaled.reason, "loss_scale is not a positive number");
  // Boxes that belong to no single object: each view shows a different place.
  std::vector<BoxView> views = ringViews(truth, 6, 2.0, 90.0);
  for (size_t i = 0; i < views.size(); ++i) {
    const double shift = (i % 2 ? 1.0 : -1.0) * 150.0;
    views[i].box = Box(views[i].box.x1 + shift, views[i].box.y1, views[i].box.x2 + shift, views[i].box.y2);
  }
  const BoxEllipsoidResult bad = buildEllipsoidFromBoxes(kK, views);
  EXPECT_NE(bad.status, BoxEllipsoidStatus::Ok);
  // Non-finite boxes are skipped, never propagated.
  std::vector<BoxView> with_nan = ringViews(truth, 6, 2.0, 90.0);
  with_nan[0].box.x1 = std::nan("");
  const BoxEllipsoidResult r = buildEllipsoidFromBoxes(kK, with_nan);
  EXPECT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.views_used, 5);
  // A camera that faces away from where the other views' rays meet, its box on its optical
  // axis, whose line runs back through them: no object behind a camera is fitted.
  std::vector<BoxView> away = ringViews(truth, 6, 2.0, 90.0);
  const Eigen::Vector3d eye = away[0].pose.center();
  const double hw = 0.5 * away[0].box.width(), hh = 0.5 * away[0].box.height();
  away.push_back({Pose::lookAt(eye, 2.0 * eye - truth.center()), Box(kK.cx - hw, kK.cy - hh, kK.cx + hw, kK.cy + hh)});
  const BoxEllipsoidResult behind = buildEllipsoidFromBoxes(kK, away);
  EXPECT_EQ(behind.status, BoxEllipsoidStatus::BehindCamera);
  EXPECT_EQ(std::string(toString(behind.status)), "behind camera");
  // Poses of the wrong convention (camera->world read as world->camera) fit nothing either.
  std::vector<BoxView> inverted = ringViews(truth, 6, 2.0, 90.0);
  for (BoxView& v : inverted) v.pose = v.pose.inverse();
  EXPECT_FALSE(buildEllipsoidFromBoxes(kK, inverted).ok());
}

// Boxes from a 10 degree arc leave the depth of a thin object (a book, 4 x 17 x 24 cm, seen
// face-on) almost unobserved. The size prior keeps every axis within the category's bounds:
// the fit is a book-sized ellipsoid, not a disc with a sub-millimetre axis or a needle.
TEST(BoxEllipsoidBuilder, SizePriorKeepsAnUnobservedAxisNearTheCategorysSize) {
  const Eigen::Vector3d book_axes = typicalSemiAxes(73);
  const Ellipsoid truth(Eigen::Vector3d(0.5, 1.0, 0.4), Eigen::Vector3d(book_axes(0), book_axes(1), book_axes(2)),
                        Eigen::Matrix3d::Identity());  // thin along x, which the cameras look along
  const std::vector<BoxView> views = ringViews(truth, 8, 1.5, 10.0);
  BoxSizePrior prior;
  prior.typical_semi_axes = book_axes;
  const BoxEllipsoidResult r = buildEllipsoidFromBoxes(kK, views, {}, prior);  // without it: an axis of 0.08 mm
  ASSERT_TRUE(r.ok()) << r.reason;
  const Eigen::Vector3d axes = r.ellipsoid.axes();
  EXPECT_GE(axes.minCoeff(), book_axes.minCoeff() / prior.range_factor - 1e-9);
  EXPECT_LE(axes.maxCoeff(), book_axes.maxCoeff() * prior.range_factor + 1e-9);
  // The extent along the viewing direction (world x) is within a factor 3 of the book's.
  const double depth_extent = std::sqrt((r.ellipsoid.shapeMatrix())(0, 0));
  EXPECT_GT(depth_extent, book_axes(0) / 3.0);
  EXPECT_LT(depth_extent, book_axes(0) * 3.0);
  EXPECT_GT(r.median_iou, 0.85);
}

// Sizes exist for all 80 categories, are positive and sorted; unknown ids get a generic size.
TEST(CategorySizes, PlausibleForEveryCocoCategory) {
  for (int c = 0; c < 80; ++c) {
    const Eigen::Vector3d a = typicalSemiAxes(c);
    EXPECT_GT(a(0), 0.004) << c;
    EXPECT_LE(a(0), a(1)) << c;
    EXPECT_LE(a(1), a(2)) << c;
  }
  EXPECT_NEAR(typicalSemiAxes(41).maxCoeff(), 0.055, 1e-9);  // a cup: 11 cm tall
  EXPECT_EQ(typicalSemiAxes(-1), typicalSemiAxes(80));
}

}  // namespace
}  // namespace ellreloc

namespace ellreloc {
namespace {

// Two faces of a box seen from one corner: PCA tilts towards the diagonal, the smallest
// enclosing rectangle does not.
TEST(EllipsoidBuilder, MinAreaRectangleYawOnAnLShapedFootprint) {
  Cuboid truth;
  truth.rotation = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  truth.half = Eigen::Vector3d(0.4, 0.2, 0.3);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j <= 10; ++j) {
      const double s = -1.0 + i / 20.0, z = -1.0 + j / 5.0;
      pts.push_back(truth.rotation * Eigen::Vector3d(s * 0.4, -0.2, z * 0.3));                  // long face
      if (i % 2 == 0) pts.push_back(truth.rotation * Eigen::Vector3d(-0.4, s * 0.2, z * 0.3));  // short face
    }
  EllipsoidBuilderOptions pca;
  pca.yaw = YawMethod::Pca;
  const auto a = buildEllipsoid(pts);  // the default: the smallest rectangle
  const auto b = buildEllipsoid(pts, pca);
  ASSERT_TRUE(a && b);
  EXPECT_LT(axisAngleModPiDeg(a->cuboid.rotation.col(0), truth.rotation.col(0)), 0.01);
  EXPECT_NEAR(a->cuboid.half(0), 0.4, 0.01);
  EXPECT_NEAR(a->cuboid.half(1), 0.2, 0.01);
  EXPECT_GT(axisAngleModPiDeg(b->cuboid.rotation.col(0), truth.rotation.col(0)), 1.0);  // PCA's bias
}

}  // namespace
}  // namespace ellreloc

namespace ellreloc {
namespace {

// A box's surface (1 mm noise) with a few stray points beside one end of a long side (a mask
// bleeding onto the table): the smallest rectangle around the hull tilts to take them in; the
// yaw polished to the smallest percentile rectangle stays with the box.
TEST(EllipsoidBuilder, StrayPointsDoNotTiltTheYaw) {
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.001);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> built_errors, hull_errors;
  for (int trial = 0; trial < 20; ++trial) {
    Cuboid truth;
    truth.rotation = Eigen::AngleAxisd(0.15 * trial, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    truth.half = Eigen::Vector3d(0.12, 0.06, 0.03);
    std::vector<Eigen::Vector3d> pts = cuboidSurface(truth, 400, 0, rng);
    for (Eigen::Vector3d& p : pts) p += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    for (int i = 0; i < 12; ++i)  // up to 1.5 cm beyond the side, along its last 4 cm
      pts.push_back(truth.rotation * Eigen::Vector3d(0.08 + 0.04 * u(rng), 0.06 + 0.015 * u(rng), -0.03));
    std::vector<Eigen::Vector2d> ground;
    for (const Eigen::Vector3d& p : pts) ground.push_back(p.head<2>());
    const auto built = buildEllipsoid(pts);
    const auto hull = detail::minAreaRectangleAxis(ground);
    ASSERT_TRUE(built && hull);
    built_errors.push_back(axisAngleModPiDeg(built->cuboid.rotation.col(0), truth.rotation.col(0)));
    hull_errors.push_back(axisAngleModPiDeg(Eigen::Vector3d(hull->x(), hull->y(), 0.0), truth.rotation.col(0)));
  }
  std::sort(built_errors.begin(), built_errors.end());
  std::sort(hull_errors.begin(), hull_errors.end());
  EXPECT_LT(built_errors[10], 0.5 * hull_errors[10]) << built_errors[10] << " " << hull_errors[10];
}

// The smallest rectangle around points rests on an edge of their hull, so trying the direction
// of every pair of points finds its area too; points inside the hull (most of a footprint,
// dropped before the hull is built) change nothing.
TEST(EllipsoidBuilder, MinAreaRectangleIsTheSmallestOverEveryPairsDirection) {
  std::mt19937 rng(8);
  std::normal_distribution<double> g(0.0, 1.0);
  const auto areaAlong = [](const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector2d& axis) {
    const Eigen::Vector2d u = axis.normalized(), v(-u.y(), u.x());
    double u_lo = 1e300, u_hi = -1e300, v_lo = 1e300, v_hi = -1e300;
    for (const Eigen::Vector2d& q : pts)
      u_lo = std::min(u_lo, u.dot(q)), u_hi = std::max(u_hi, u.dot(q)), v_lo = std::min(v_lo, v.dot(q)),
      v_hi = std::max(v_hi, v.dot(q));
    return (u_hi - u_lo) * (v_hi - v_lo);
  };
  for (int trial = 0; trial < 10; ++trial) {
    std::vector<Eigen::Vector2d> pts;
    const double c = std::cos(0.3 * trial), s = std::sin(0.3 * trial);
    for (int i = 0; i < 150; ++i) {
      const Eigen::Vector2d local(0.4 * g(rng), 0.1 * g(rng));  // elongated, turned
      pts.emplace_back(c * local.x() - s * local.y() + 2.0, s * local.x() + c * local.y() - 1.0);
    }
    double best = 1e300;
    for (size_t i = 0; i < pts.size(); ++i)
      for (size_t j = i + 1; j < pts.size(); ++j) best = std::min(best, areaAlong(pts, pts[j] - pts[i]));
    const auto axis = detail::minAreaRectangleAxis(pts);
    ASSERT_TRUE(axis);
    EXPECT_NEAR(areaAlong(pts, *axis), best, 1e-12 * best) << trial;
  }
}

// The yaw search's quantile pairs are interpolatedQuantile's to the bit: near the ends from the
// few smallest and largest values, elsewhere by reordering; with ties, at every size around the
// switch between the two and in either order of the two quantiles.
TEST(EllipsoidBuilder, QuantilePairsAreInterpolatedQuantiles) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> coarse(0, 40);  // ties
  std::normal_distribution<double> fine(0.0, 1.0);
  std::vector<double> scratch;
  const std::vector<std::pair<double, double>> quantiles = {{0.01, 0.99}, {0.02, 0.98}, {0.0, 1.0}, {0.1, 0.9},
                                                            {0.5, 0.5},   {0.99, 0.01}, {-1.0, 2.0}};
  for (const size_t n : {1, 2, 3, 31, 32, 33, 40, 100, 511, 512, 1000, 1600, 5000}) {
    for (const bool ties : {false, true}) {
      std::vector<double> values(n);
      for (double& v : values) v = ties ? coarse(rng) * 0.25 : fine(rng);
      for (const auto& [low, high] : quantiles) {
        const auto [q_low, q_high] = detail::quantilePair(values, low, high, &scratch);
        EXPECT_EQ(q_low, interpolatedQuantile(values, low)) << n << " " << low;
        EXPECT_EQ(q_high, interpolatedQuantile(values, high)) << n << " " << high;
      }
    }
  }
}

}  // namespace
}  // namespace ellreloc
