#include <gtest/gtest.h>

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/mask.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/observe/ellipse_fit.hpp"
#include "ellreloc/observe/observe.hpp"
#include "ellreloc/observe/regular_mask.hpp"
#include "fixtures/data_dir.hpp"
#include "fixtures/mask_outline.hpp"
#include "fixtures/mask_shapes.hpp"
#include "fixtures/random_geometry.hpp"

using namespace ellreloc;
using ellreloc::test::uniform;

namespace {

/// Moments by visiting every decoded pixel: the independent check of rleMoments.
MaskMoments pixelMoments(const BinaryMask& m) {
  double n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x)
      if (m.at(x, y)) n += 1, sx += x, sy += y, sxx += double(x) * x, syy += double(y) * y, sxy += double(x) * y;
  MaskMoments r;
  r.area = n;
  r.mean = {sx / n, sy / n};
  r.covariance << sxx / n - r.mean(0) * r.mean(0) + 1.0 / 12, sxy / n - r.mean(0) * r.mean(1),
      sxy / n - r.mean(0) * r.mean(1), syy / n - r.mean(1) * r.mean(1) + 1.0 / 12;
  return r;
}

}  // namespace

TEST(Mask, RleMomentsEqualPixelMomentsOnRealMasks) {
  for (const auto& frame : io::readDetections(test::dataPath("labelme_masks/detections.json"))) {
    for (const auto& det : frame.detections) {
      const auto mask = decodeMask(*det.mask);
      ASSERT_TRUE(mask.has_value());
      const MaskMoments a = *rleMoments(*det.mask), b = pixelMoments(*mask);
      EXPECT_EQ(a.area, b.area);
      EXPECT_LT((a.mean - b.mean).norm(), 1e-9);
      EXPECT_LT((a.covariance - b.covariance).norm(), 1e-6);
      // The README's boxes are the masks' outer pixel edges.
      EXPECT_DOUBLE_EQ(a.bounds.x1, det.bbox.x1);
      EXPECT_DOUBLE_EQ(a.bounds.y2, det.bbox.y2);
      // Encoding the decoded mask gives the same runs back.
      EXPECT_EQ(encodeMask(*mask).counts, det.mask->counts);
    }
  }
}

TEST(Mask, MomentEllipseOfARasterisedEllipse) {
  std::mt19937 rng(91);
  for (int i = 0; i < 50; ++i) {
    const Ellipse e({uniform(rng, 80, 120), uniform(rng, 80, 120)}, {uniform(rng, 15, 60), uniform(rng, 10, 40)},
                    uniform(rng, -3, 3));
    const BinaryMask m = test::rasterEllipse(e, 200, 200);
    const auto fit = momentEllipse(*rleMoments(encodeMask(m)));
    ASSERT_TRUE(fit.has_value());
    EXPECT_LT(wasserstein2(*fit, e), 0.3);  // pixels
  }
}

TEST(EllipseFit, DirectFitIsExactOnEllipsePointsAndRobustToNoise) {
  std::mt19937 rng(92);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    const Ellipse e({uniform(rng, 50, 600), uniform(rng, 50, 400)}, {uniform(rng, 20, 120), uniform(rng, 20, 120)},
                    uniform(rng, -M_PI, M_PI));
    auto pts = e.sampleBoundary(40);
    const auto exact = fitEllipseDirect(pts);
    ASSERT_TRUE(exact.has_value());
    EXPECT_LT(wasserstein2(*exact, e), 1e-6 * e.axes()(0));
    for (auto& p : pts) p += Eigen::Vector2d(noise(rng), noise(rng));
    const auto noisy = fitEllipseDirect(pts);
    ASSERT_TRUE(noisy.has_value());
    EXPECT_LT(wasserstein2(*noisy, e), 3.0);
  }
  // Only an arc of the ellipse: still the right ellipse from exact points.
  const Ellipse e({300, 200}, {80, 40}, 0.3);
  std::vector<Eigen::Vector2d> arc;
  for (int k = 0; k < 30; ++k) arc.push_back(e.pointAt(-1.0 + 2.0 * k / 29));
  EXPECT_LT(wasserstein2(*fitEllipseDirect(arc), e), 1e-6);
  // Degenerate input.
  EXPECT_FALSE(fitEllipseDirect({{0, 0}, {1, 1}, {2, 2}}).has_value());
  std::vector<Eigen::Vector2d> line;
  for (int k = 0; k < 10; ++k) line.emplace_back(k, 2 * k);
  EXPECT_FALSE(fitEllipseDirect(line).has_value());
}

TEST(EllipseFit, OutlineDropsTheImageBorderSoTruncatedObjectsFitWell) {
  // An ellipse half outside the image: the direct fit on the outline without border points
  // recovers it; the moment ellipse of the visible part cannot.
  const Ellipse e({-10, 100}, {60, 35}, 0.2);
  const BinaryMask m = test::rasterEllipse(e, 200, 200);
  bool border = false;
  const auto pts = test::maskOutline(m, &border);
  EXPECT_TRUE(border);
  for (const auto& p : pts) EXPECT_GE(p(0), 0.0);  // nothing on the border line x = -0.5
  const auto direct = fitEllipseDirect(pts);
  ASSERT_TRUE(direct.has_value());
  EXPECT_LT(wasserstein2(*direct, e), 1.5);
  const auto moments = momentEllipse(*rleMoments(encodeMask(m)));
  EXPECT_GT(wasserstein2(*moments, e), 10.0);
}

// The library's outline, from the runs, is the decoded mask's outline for shapes whose columns
// have no gaps (an ellipse), wherever the image border cuts them: the same edge midpoints, the
// border's dropped, and the same verdict on touching the border.
TEST(EllipseFit, RleOutlineIsTheDecodedOutlineAndDropsEveryBorder) {
  const int W = 200, H = 150;
  const Ellipse shapes[] = {
      Ellipse({100, 75}, {40, 25}, 0.3),   // inside
      Ellipse({-10, 70}, {50, 30}, 0.2),   // cut by the left border
      Ellipse({195, 60}, {30, 45}, -0.4),  // the right
      Ellipse({90, 5}, {60, 20}, 0.1),     // the top
      Ellipse({120, 148}, {35, 25}, 0.7),  // the bottom
      Ellipse({190, 140}, {40, 30}, 0.5),  // a corner
  };
  int touching = 0;
  for (const Ellipse& e : shapes) {
    const BinaryMask m = test::rasterEllipse(e, W, H);
    bool expected_border = false, border = false;
    std::vector<Eigen::Vector2d> expected = test::maskOutline(m, &expected_border);
    std::vector<Eigen::Vector2d> ours = rleOutline(encodeMask(m), &border);
    const auto byPosition = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
      return a(0) != b(0) ? a(0) < b(0) : a(1) < b(1);
    };
    std::sort(expected.begin(), expected.end(), byPosition);
    std::sort(ours.begin(), ours.end(), byPosition);
    EXPECT_EQ(ours, expected) << e.center().transpose();
    EXPECT_EQ(border, expected_border) << e.center().transpose();
    touching += border;
    for (const Eigen::Vector2d& p : ours) {
      EXPECT_TRUE(p(0) > -0.5 && p(0) < W - 0.5 && p(1) > -0.5 && p(1) < H - 0.5) << p.transpose();
    }
  }
  EXPECT_EQ(touching, 5);
}

TEST(EllipseFit, ProjectivelyInscribedEllipseIsTheImageOfTheRectanglesEllipse) {
  // A planar rectangle seen in perspective: its inscribed ellipse, as a very flat ellipsoid,
  // projects to the ellipse computed from the four projected corners.
  std::mt19937 rng(93);
  const Intrinsics K = test::testIntrinsics();
  for (int i = 0; i < 100; ++i) {
    const Eigen::Matrix3d R = test::randomRotation(rng);
    const Eigen::Vector3d c(uniform(rng, -0.3, 0.3), uniform(rng, -0.3, 0.3), 0.0);
    const double a = uniform(rng, 0.1, 0.5), b = uniform(rng, 0.1, 0.5);
    const Pose pose = test::randomLookAtPose(rng);
    std::array<Eigen::Vector2d, 4> corners;
    const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
    bool visible = true;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d x = pose.transform(c + R * Eigen::Vector3d(sx[k] * a, sy[k] * b, 0));
      visible = visible && x(2) > 0.1;
      corners[k] = K.project(x);
    }
    if (!visible) continue;
    const Ellipsoid flat(c, {a, b, 1e-7}, R);
    const Projection p = project(flat, K, pose);
    if (!p) continue;
    const auto e = projectivelyInscribedEllipse(corners);
    ASSERT_TRUE(e.has_value());
    EXPECT_LT(wasserstein2(*e, p.ellipse), 1e-3 * p.ellipse.axes()(0)) << i;
    // Tangent to each side at the image of its midpoint.
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d mid = pose.transform(
          c + R * Eigen::Vector3d(0.5 * (sx[k] + sx[(k + 1) % 4]) * a, 0.5 * (sy[k] + sy[(k + 1) % 4]) * b, 0));
      EXPECT_NEAR(e->mahalanobisRadius(K.project(mid)), 1.0, 1e-6);
    }
  }
  // Degenerate quadrilaterals.
  EXPECT_FALSE(projectivelyInscribedEllipse({Eigen::Vector2d(0, 0), {1, 0}, {2, 0}, {3, 0}}).has_value());
}

TEST(EllipseFit, RealMasksAgreeWithOpenCvFitEllipse) {
  // For each labelme instance: the direct fit on the outline against cv::fitEllipse on the
  // points of all outer OpenCV contours of the same mask. Both are algebraic least-squares fits
  // of one outline, so their centres agree within a few pixels; on these non-elliptical shapes
  // (people, buses) their sizes differ by up to ~20%, because cv::fitEllipse normalises the
  // conic differently from the ellipse-specific constraint 4ac - b^2 = 1.
  for (const auto& frame : io::readDetections(test::dataPath("labelme_masks/detections.json"))) {
    for (const auto& det : frame.detections) {
      const BinaryMask m = *decodeMask(*det.mask);
      cv::Mat img(m.height, m.width, CV_8U);
      for (int y = 0; y < m.height; ++y)
        for (int x = 0; x < m.width; ++x) img.at<uint8_t>(y, x) = m.at(x, y) ? 255 : 0;
      std::vector<std::vector<cv::Point>> contours;
      cv::findContours(img, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
      std::vector<cv::Point> all;
      for (const auto& c : contours) all.insert(all.end(), c.begin(), c.end());
      const cv::RotatedRect cvfit = cv::fitEllipse(all);
      const auto ours = fitEllipseDirect(test::maskOutline(m));
      ASSERT_TRUE(ours.has_value());
      const double size = std::sqrt(ours->axes().prod());
      EXPECT_LT((ours->center() - Eigen::Vector2d(cvfit.center.x, cvfit.center.y)).norm(), 0.1 * size + 3.0)
          << frame.file_name;
      const double cv_a = 0.5 * std::max(cvfit.size.width, cvfit.size.height);
      const double cv_b = 0.5 * std::min(cvfit.size.width, cvfit.size.height);
      EXPECT_NEAR(ours->axes()(0), cv_a, 0.25 * cv_a) << frame.file_name;
      EXPECT_NEAR(ours->axes()(1), cv_b, 0.25 * cv_b) << frame.file_name;
    }
  }
}

TEST(Mask, CropDecodingMatchesFullDecoding) {
  for (const auto& frame : io::readDetections(test::dataPath("labelme_masks/detections.json"))) {
    for (const auto& det : frame.detections) {
      const BinaryMask full = *decodeMask(*det.mask);
      const BinaryMask crop = *decodeMaskCrop(*det.mask);
      EXPECT_EQ(crop.count(), full.count());
      EXPECT_EQ(encodeMask(crop).counts, det.mask->counts);
      EXPECT_EQ(test::maskOutline(crop), test::maskOutline(full));
      EXPECT_DOUBLE_EQ(crop.x0 - 0.5, det.bbox.x1);
      EXPECT_DOUBLE_EQ(crop.y0 + crop.height - 0.5, det.bbox.y2);
      // The data's boxes are the masks' outer pixel edges: maskBox gives them from the runs.
      const Box box = *maskBox(*det.mask);
      EXPECT_EQ(Eigen::Vector4d(box.x1, box.y1, box.x2, box.y2),
                Eigen::Vector4d(det.bbox.x1, det.bbox.y1, det.bbox.x2, det.bbox.y2));
    }
  }
  EXPECT_FALSE(decodeMaskCrop(encodeMask(BinaryMask(10, 10))).has_value());  // empty
  EXPECT_FALSE(maskBox(encodeMask(BinaryMask(10, 10))).has_value());
}

namespace {

// COCO runs written out pixel by pixel: column-major over the whole image, starting with zeros.
std::vector<uint32_t> runsOfEveryPixel(const BinaryMask& full) {
  std::vector<uint32_t> runs{0};
  bool on = false;
  for (int x = 0; x < full.width; ++x)
    for (int y = 0; y < full.height; ++y) {
      if ((full.at(x, y) != 0) != on) on = !on, runs.push_back(0);
      ++runs.back();
    }
  return runs;
}

}  // namespace

TEST(Mask, CropsGrownByAMarginEncodeAsTheWholeImage) {
  // Random specks and blocks in images of random sizes, some touching the border; crops grown by
  // margins from none to wider than the image: the runs of each crop are those of a scan of
  // every pixel, and its pixels are the whole mask's inside the crop (nothing set outside).
  std::mt19937 rng(17);
  const auto draw = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  for (int trial = 0; trial < 300; ++trial) {
    const int W = draw(1, 40), H = draw(1, 30);
    BinaryMask full(H, W);
    const int x0 = draw(0, W - 1), y0 = draw(0, H - 1);
    const int x1 = draw(x0, W - 1), y1 = draw(y0, H - 1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) full.at(x, y) = std::bernoulli_distribution(trial % 3 == 0 ? 1.0 : 0.4)(rng);
    full.at(x0, y0) = 1;
    const RleMask rle{H, W, runsOfEveryPixel(full)};
    ASSERT_EQ(encodeMask(full).counts, rle.counts) << trial;
    const PixelBounds b = *maskPixelBounds(rle);
    for (int margin : {0, 1, 3, 50}) {
      const BinaryMask crop = *decodeMaskCrop(rle, margin);
      EXPECT_EQ(crop.x0, std::max(b.xmin - margin, 0)) << trial;
      EXPECT_EQ(crop.y0, std::max(b.ymin - margin, 0)) << trial;
      EXPECT_EQ(crop.x0 + crop.width - 1, std::min(b.xmax + margin, W - 1)) << trial;
      EXPECT_EQ(crop.y0 + crop.height - 1, std::min(b.ymax + margin, H - 1)) << trial;
      EXPECT_EQ(crop.count(), full.count()) << trial;
      for (int y = 0; y < crop.height; ++y)
        for (int x = 0; x < crop.width; ++x) ASSERT_EQ(crop.at(x, y), full.at(crop.x0 + x, crop.y0 + y)) << trial;
      EXPECT_EQ(encodeMask(crop).counts, rle.counts) << trial << " margin " << margin;
    }
  }
  // A window wider than the image, or outside it, is cut to it.
  BinaryMask one(4, 5);
  one.at(2, 1) = 1;
  const auto set = [&](int x, int y) { return one.at(x, y) != 0; };
  EXPECT_EQ(encodeRunsInWindow(4, 5, -3, 9, -2, 7, set).counts, runsOfEveryPixel(one));
  EXPECT_EQ(encodeRunsInWindow(4, 5, 7, 9, 0, 4, set).counts, std::vector<uint32_t>{20});
  EXPECT_EQ(encodeRunsInWindow(4, 5, 2, 3, 1, 2, set).counts, (std::vector<uint32_t>{9, 1, 10}));
  // An empty mask: one run of zeros over the image, as a scan of every pixel gives.
  for (const auto& [h, w] : {std::pair(4, 5), std::pair(480, 640), std::pair(1, 1)}) {
    EXPECT_EQ(emptyRle(h, w).counts, runsOfEveryPixel(BinaryMask(h, w))) << h << "x" << w;
    EXPECT_TRUE(emptyRle(h, w).isConsistent()) << h << "x" << w;
  }
}

TEST(Mask, PolygonMaskEqualsPixelCentreRasterisation) {
  // Random star-shaped (concave) polygons with non-integer vertices, some crossing the image
  // border, against the row-wise ray-casting rasteriser of the fixtures.
  std::mt19937 rng(7);
  const int W = 97, H = 61;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector2d c(uniform(rng, -10, W + 10), uniform(rng, -10, H + 10));
    const int n = 3 + trial % 12;
    std::vector<Eigen::Vector2d> poly;
    for (int k = 0; k < n; ++k) {
      const double a = 2 * M_PI * (k + uniform(rng, 0.0, 0.9)) / n, r = uniform(rng, 2, 40);
      poly.push_back(c + r * Eigen::Vector2d(std::cos(a), std::sin(a)));
    }
    const RleMask got = polygonMask(poly, H, W);
    ASSERT_TRUE(got.isConsistent()) << trial;
    EXPECT_EQ(got.counts, encodeMask(test::rasterPolygon(poly, W, H)).counts) << trial;
  }
  // Degenerate input: an empty mask, never a crash.
  EXPECT_EQ(polygonMask({{1, 1}, {5, 1}}, H, W).counts, std::vector<uint32_t>{W * H});
  EXPECT_EQ(polygonMask({{1, 1}, {NAN, 1}, {3, 9}}, H, W).counts, std::vector<uint32_t>{W * H});
  EXPECT_EQ(polygonMask({{-50, -50}, {-40, -50}, {-45, -40}}, H, W).counts, std::vector<uint32_t>{W * H});
}

namespace {

/// The convex hull of points, by OpenCV (which picks the vertices in float): the independent
/// check of the library's hulls.
std::vector<Eigen::Vector2d> cvHull(const std::vector<Eigen::Vector2d>& points) {
  std::vector<cv::Point2f> in;
  for (const auto& p : points) in.emplace_back(static_cast<float>(p(0)), static_cast<float>(p(1)));
  std::vector<int> indices;
  cv::convexHull(in, indices);
  std::vector<Eigen::Vector2d> hull;
  for (int i : indices) hull.push_back(points[static_cast<size_t>(i)]);
  return hull;
}

double polygonArea(const std::vector<Eigen::Vector2d>& p) {
  double a = 0;
  for (size_t i = 0; i < p.size(); ++i) a += p[i](0) * p[(i + 1) % p.size()](1) - p[i](1) * p[(i + 1) % p.size()](0);
  return 0.5 * std::abs(a);
}

}  // namespace

TEST(EllipseFit, RleConvexHullIsTheHullOfThePixelSquares) {
  std::mt19937 rng(17);
  for (int i = 0; i < 30; ++i) {
    BinaryMask m = test::rasterEllipse(test::randomEllipse(rng), 640, 480);
    test::addBoundaryNoise(m, rng, 0.5);
    std::vector<Eigen::Vector2d> corners;
    for (int y = 0; y < m.height; ++y)
      for (int x = 0; x < m.width; ++x)
        if (m.at(x, y))
          for (double dx : {-0.5, 0.5})
            for (double dy : {-0.5, 0.5}) corners.emplace_back(x + dx, y + dy);
    if (corners.empty()) continue;
    const std::vector<Eigen::Vector2d> hull = rleConvexHull(encodeMask(m));
    EXPECT_NEAR(polygonArea(hull), polygonArea(cvHull(corners)), 1e-6) << i;
  }
  EXPECT_TRUE(rleConvexHull(encodeMask(BinaryMask(48, 64))).empty());
}

TEST(EllipseFit, HullEllipseOfABoxSilhouetteIsTheImageOfItsInscribedEllipsoid) {
  // In parallel projection a box's silhouette is the hexagon spanned by the images g_i of its
  // half-edges, and its inscribed ellipsoid projects to the ellipse of shape sum g_i g_i^T.
  std::mt19937 rng(29);
  int tested = 0;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Matrix3d R = test::randomRotation(rng);
    const Eigen::Vector3d half(uniform(rng, 0.05, 0.5), uniform(rng, 0.05, 0.5), uniform(rng, 0.05, 0.5));
    const Eigen::Matrix<double, 2, 3> A = 400.0 * test::randomRotation(rng).topRows<2>();  // px per metre
    const Eigen::Vector2d centre(uniform(rng, 100, 500), uniform(rng, 100, 400));
    const Eigen::Matrix<double, 2, 3> G = A * R * half.asDiagonal();  // columns: the g_i
    // Two images of edges closer than 10 degrees to parallel are merged by design (a
    // silhouette cannot tell them from one edge): not this test's case.
    bool separable = true;
    for (int a = 0; a < 3; ++a)
      for (int b = a + 1; b < 3; ++b)
        separable = separable && std::abs(G.col(a).normalized().dot(G.col(b).normalized())) < std::cos(12.0 * M_PI / 180.0);
    if (!separable) continue;
    ++tested;
    std::vector<Eigen::Vector2d> corners;
    for (double sx : {-1.0, 1.0})
      for (double sy : {-1.0, 1.0})
        for (double sz : {-1.0, 1.0}) corners.push_back(centre + G * Eigen::Vector3d(sx, sy, sz));
    const Ellipse truth = *Ellipse::fromGaussian(centre, G * G.transpose());
    const auto e = hullEllipse(cvHull(corners));
    ASSERT_TRUE(e.has_value());
    EXPECT_LT(wasserstein2(*e, truth), 1e-6 * truth.axes()(1)) << i;
  }
  EXPECT_GT(tested, 100);
  // A face-on box, a parallelogram: the ellipse touches each side at its midpoint.
  const std::vector<Eigen::Vector2d> quad = {{100, 100}, {300, 140}, {330, 260}, {130, 220}};
  const auto e = hullEllipse(quad);
  ASSERT_TRUE(e.has_value());
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(e->mahalanobisRadius(0.5 * (quad[k] + quad[(k + 1) % 4])), 1.0, 1e-9);
}

TEST(EllipseFit, HullEllipseOfARoundSilhouetteIsTheSilhouette) {
  std::mt19937 rng(31);
  for (int i = 0; i < 50; ++i) {
    const Ellipse truth = test::randomEllipse(rng);
    const auto e = hullEllipse(cvHull(truth.sampleBoundary(400)));
    ASSERT_TRUE(e.has_value());
    EXPECT_LT(wasserstein2(*e, truth), 0.01 * std::sqrt(truth.axes().prod())) << i;
  }
  // No area, no ellipse.
  EXPECT_FALSE(hullEllipse({{0, 0}, {1, 1}}).has_value());
  EXPECT_FALSE(hullEllipse({{0, 0}, {1, 1}, {2, 2}}).has_value());
}

TEST(EllipseFit, HullFitOfBoxMasksInPerspectiveBeatsTheBoxAndTheOutline) {
  // Boxes at 1-3 m seen in perspective, masks with boundary noise: the truth is the projection
  // of the ellipsoid inscribed in the box, which the silhouette overreaches.
  std::mt19937 rng(37);
  const Intrinsics K = test::testIntrinsics();
  std::vector<double> hull_err, box_err, direct_err;
  for (int i = 0; i < 120; ++i) {
    const Eigen::Vector3d half(uniform(rng, 0.05, 0.3), uniform(rng, 0.05, 0.3), uniform(rng, 0.05, 0.3));
    const Eigen::Matrix3d R = test::randomRotation(rng);
    const Eigen::Vector3d centre(uniform(rng, -0.3, 0.3), uniform(rng, -0.2, 0.2), uniform(rng, 1.0, 3.0));
    std::vector<Eigen::Vector2d> image;
    for (double sx : {-1.0, 1.0})
      for (double sy : {-1.0, 1.0})
        for (double sz : {-1.0, 1.0}) image.push_back(K.project(centre + R * half.cwiseProduct(Eigen::Vector3d(sx, sy, sz))));
    const Projection truth = project(Ellipsoid(centre, half, R), K, Pose());
    ASSERT_TRUE(truth);
    BinaryMask m = test::rasterPolygon(cvHull(image), K.width, K.height);
    test::addBoundaryNoise(m, rng, 0.5);
    const RleMask rle = encodeMask(m);
    const auto moments = rleMoments(rle);
    if (!moments || moments->area < 200) continue;
    const Box& b = moments->bounds;  // cut by the image border: not this test's case
    if (b.x1 < 0 || b.y1 < 0 || b.x2 > K.width - 1 || b.y2 > K.height - 1) continue;
    const double scale = std::sqrt(truth.ellipse.axes().prod());
    hull_err.push_back(wasserstein2(*fitMaskEllipse(rle, MaskFitMethod::Hull, nullptr), truth.ellipse) / scale);
    box_err.push_back(wasserstein2(*Ellipse::inscribedInBox(moments->bounds), truth.ellipse) / scale);
    direct_err.push_back(wasserstein2(*fitMaskEllipse(rle, MaskFitMethod::Direct, nullptr), truth.ellipse) / scale);
  }
  ASSERT_GT(hull_err.size(), 80u);
  const auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  EXPECT_LT(median(hull_err), 0.5 * median(box_err));
  EXPECT_LT(median(hull_err), 0.5 * median(direct_err));
}
