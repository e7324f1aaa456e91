// Lens distortion: the model against OpenCV's projectPoints and undistortPoints (the same
// radial-tangential model, computed independently), the inverse, the invertibility check, and
// boxes and ellipses moved to the pinhole image.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <random>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/distortion.hpp"

using namespace ellreloc;

namespace {

// TUM fr2's factory calibration (shared/data/tum_fr2_desk/camera.yaml).
const Intrinsics kFr2(520.90862, 521.007327, 325.141442, 249.701764, 640, 480);
const Distortion kFr2Lens{0.231222, -0.784899, -0.003257, -0.000105, 0.917205};

cv::Mat cameraMatrix(const Intrinsics& K) { return (cv::Mat_<double>(3, 3) << K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1); }
cv::Mat coefficients(const Distortion& d) { return (cv::Mat_<double>(1, 5) << d.k1, d.k2, d.p1, d.p2, d.k3); }

}  // namespace

TEST(Distortion, DistortsAsOpenCvProjects) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  std::vector<cv::Point3d> points;
  for (int i = 0; i < 200; ++i) points.emplace_back(u(rng), u(rng), 1.0);
  std::vector<cv::Point2d> projected;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), cameraMatrix(kFr2), coefficients(kFr2Lens),
                    projected);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d ours =
        kFr2Lens.distortPixel(kFr2, {kFr2.fx * points[i].x + kFr2.cx, kFr2.fy * points[i].y + kFr2.cy});
    EXPECT_NEAR(ours.x(), projected[i].x, 1e-9);
    EXPECT_NEAR(ours.y(), projected[i].y, 1e-9);
  }
}

TEST(Distortion, UndistortsEveryPixelOfTheImageAsOpenCv) {
  std::vector<cv::Point2d> raw;
  for (int y = 0; y < 480; y += 16)
    for (int x = 0; x < 640; x += 16) raw.emplace_back(x, y);
  raw.emplace_back(-0.5, -0.5);
  raw.emplace_back(639.5, 479.5);
  std::vector<cv::Point2d> theirs;
  // OpenCV iterates a fixed point; enough iterations to converge as far as ours does.
  cv::undistortPoints(raw, theirs, cameraMatrix(kFr2), coefficients(kFr2Lens), cv::noArray(), cameraMatrix(kFr2),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-15));
  double worst = 0.0;
  for (size_t i = 0; i < raw.size(); ++i) {
    const std::optional<Eigen::Vector2d> ours = kFr2Lens.undistortPixel(kFr2, {raw[i].x, raw[i].y});
    ASSERT_TRUE(ours) << raw[i];
    worst = std::max(worst, (*ours - Eigen::Vector2d(theirs[i].x, theirs[i].y)).norm());
    // And back: the inverse is exact to the model.
    EXPECT_LT((kFr2Lens.distortPixel(kFr2, *ours) - Eigen::Vector2d(raw[i].x, raw[i].y)).norm(), 1e-6);
  }
  EXPECT_LT(worst, 1e-4);
  // The lens moves the corners of fr2's images by about 15 pixels: no rounding to hide.
  const Eigen::Vector2d corner = *kFr2Lens.undistortPixel(kFr2, {-0.5, -0.5});
  EXPECT_GT((corner - Eigen::Vector2d(-0.5, -0.5)).norm(), 10.0);
}

// Keypoints of a raw image (a host's ORB keypoints) go where OpenCV undistorts them, keeping
// their map point; one the model cannot undo is left out and counted.
TEST(Distortion, KeypointsAreUndistortedAsOpenCvAndTheUndoableCounted) {
  std::vector<Keypoint> raw;
  std::vector<cv::Point2d> pixels;
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector2d uv(7.5 + 16.0 * i, 3.0 + 11.5 * i);
    raw.push_back({100 + i, uv});
    pixels.emplace_back(uv.x(), uv.y());
  }
  raw.insert(raw.begin() + 5, Keypoint{7, Eigen::Vector2d(std::nan(""), 10.0)});
  std::vector<cv::Point2d> theirs;
  cv::undistortPoints(pixels, theirs, cameraMatrix(kFr2), coefficients(kFr2Lens), cv::noArray(), cameraMatrix(kFr2),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-15));
  size_t left_out = 0;
  const std::vector<Keypoint> moved = undistortKeypoints(Lens{kFr2, kFr2Lens}, raw, &left_out);
  EXPECT_EQ(left_out, 1u);
  ASSERT_EQ(moved.size(), pixels.size());
  double farthest = 0.0;
  for (size_t i = 0; i < moved.size(); ++i) {
    EXPECT_EQ(moved[i].point_index, 100 + static_cast<int>(i));
    EXPECT_LT((moved[i].uv - Eigen::Vector2d(theirs[i].x, theirs[i].y)).norm(), 1e-4);
    farthest = std::max(farthest, (moved[i].uv - Eigen::Vector2d(pixels[i].x, pixels[i].y)).norm());
  }
  EXPECT_GT(farthest, 5.0);  // they did move
  // Without a lens's distortion they stay exactly where they were.
  const std::vector<Keypoint> same = undistortKeypoints(Lens{kFr2, Distortion{}}, moved);
  ASSERT_EQ(same.size(), moved.size());
  for (size_t i = 0; i < same.size(); ++i) EXPECT_EQ(same[i].uv, moved[i].uv);
}

TEST(Distortion, NoDistortionChangesNothing) {
  const Distortion none;
  EXPECT_TRUE(none.isZero());
  EXPECT_EQ(none.whyNotInvertible(kFr2), "");
  const Lens lens{kFr2, none};
  const Box box(12.5, 40.25, 300.0, 333.0);
  const std::optional<Box> same = lens.undistortBox(box);
  ASSERT_TRUE(same);
  EXPECT_NEAR(same->x1, box.x1, 1e-12);
  EXPECT_NEAR(same->y1, box.y1, 1e-12);
  EXPECT_NEAR(same->x2, box.x2, 1e-12);
  EXPECT_NEAR(same->y2, box.y2, 1e-12);
  const Ellipse e({300.0, 200.0}, {80.0, 30.0}, 0.4);
  EXPECT_LT(wasserstein2(*lens.undistortEllipse(e), e), 1e-9);
}

TEST(Distortion, TellsWhyALensCannotBeUndone) {
  EXPECT_EQ(kFr2Lens.whyNotInvertible(kFr2), "");
  // A strong barrel term folds the image over before its corners: two directions, one pixel.
  const Distortion folding{-0.9, 0, 0, 0, 0};
  EXPECT_NE(folding.whyNotInvertible(kFr2).find("folds over"), std::string::npos);
  const Distortion nan{std::nan(""), 0, 0, 0, 0};
  EXPECT_NE(nan.whyNotInvertible(kFr2).find("finite"), std::string::npos);
  EXPECT_FALSE(nan.undistort({0.1, 0.1}));
}

// The undistorted box bounds the undistorted image of everything inside the raw box, and no
// more than the outline reaches.
TEST(Distortion, AnUndistortedBoxBoundsWhatTheRawBoxHeld) {
  const Lens lens{kFr2, kFr2Lens};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const Box raw : {Box(0, 0, 120, 90), Box(500, 380, 639, 479), Box(250, 200, 400, 300), Box(10, 200, 60, 470)}) {
    const std::optional<Box> box = lens.undistortBox(raw);
    ASSERT_TRUE(box);
    Box reached(INFINITY, INFINITY, -INFINITY, -INFINITY);
    for (int i = 0; i < 4000; ++i) {
      const Eigen::Vector2d p(raw.x1 + u(rng) * raw.width(), raw.y1 + u(rng) * raw.height());
      const Eigen::Vector2d q = *lens.undistortPixel(p);
      EXPECT_TRUE(q.x() >= box->x1 - 1e-9 && q.x() <= box->x2 + 1e-9 && q.y() >= box->y1 - 1e-9 &&
                  q.y() <= box->y2 + 1e-9);
      reached = Box(std::min(reached.x1, q.x()), std::min(reached.y1, q.y()), std::max(reached.x2, q.x()),
                    std::max(reached.y2, q.y()));
    }
    EXPECT_LT(reached.x1 - box->x1, 1.0);  // random points come within a pixel of each side
    EXPECT_LT(box->x2 - reached.x2, 1.0);
    EXPECT_LT(reached.y1 - box->y1, 1.0);
    EXPECT_LT(box->y2 - reached.y2, 1.0);
  }
}

TEST(Distortion, AnEllipseOfAPolygonHasItsMoments) {
  const Ellipse e({300.0, 200.0}, {80.0, 30.0}, 0.4);
  const std::optional<Ellipse> back = Lens::ellipseOfPolygon(e.sampleBoundary(256));
  ASSERT_TRUE(back);
  EXPECT_LT((back->center() - e.center()).norm(), 1e-9);
  EXPECT_NEAR(back->axes()(0), 80.0, 0.01);  // an inscribed polygon: a little smaller
  EXPECT_NEAR(back->axes()(1), 30.0, 0.01);
  EXPECT_NEAR(back->angle(), 0.4, 1e-9);
  // Clockwise or counter-clockwise alike.
  std::vector<Eigen::Vector2d> reversed = e.sampleBoundary(256);
  std::reverse(reversed.begin(), reversed.end());
  EXPECT_NEAR(Lens::ellipseOfPolygon(reversed)->axes()(0), back->axes()(0), 1e-9);
  EXPECT_FALSE(Lens::ellipseOfPolygon({{0, 0}, {1, 1}, {2, 2}}));  // no area
}

// An ellipse near the corner of a raw fr2 image is moved and reshaped as its outline is: its
// undistorted ellipse passes within a fraction of a pixel of every undistorted outline point.
TEST(Distortion, AnUndistortedEllipseFollowsItsOutline) {
  const Lens lens{kFr2, kFr2Lens};
  const Ellipse raw({80.0, 70.0}, {60.0, 25.0}, -0.3);
  const std::optional<Ellipse> e = lens.undistortEllipse(raw);
  ASSERT_TRUE(e);
  EXPECT_GT((e->center() - raw.center()).norm(), 3.0);  // the lens moved it
  for (const Eigen::Vector2d& p : raw.sampleBoundary(64)) {
    const Eigen::Vector2d q = *lens.undistortPixel(p);
    EXPECT_NEAR(e->mahalanobisRadius(q), 1.0, 0.02);
  }
}
