#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/core/statistics.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/observe/observe.hpp"
#include "ellreloc/observe/regular_mask.hpp"
#include "ellreloc/sim/truth.hpp"
#include "fixtures/data_dir.hpp"
#include "fixtures/mask_shapes.hpp"
#include "fixtures/random_geometry.hpp"

using namespace ellreloc;
using ellreloc::test::uniform;

namespace {

using Poly = std::vector<Eigen::Vector2d>;

Eigen::Vector2d rot(const Eigen::Vector2d& v, double a) {
  return {std::cos(a) * v(0) - std::sin(a) * v(1), std::sin(a) * v(0) + std::cos(a) * v(1)};
}

Poly rectangle(std::mt19937& rng, double wmin, double wmax, double hmin, double hmax) {
  const Eigen::Vector2d c(150, 150);
  const double w = uniform(rng, wmin, wmax) / 2, h = uniform(rng, hmin, hmax) / 2, a = uniform(rng, -M_PI, M_PI);
  return {c + rot({-w, -h}, a), c + rot({w, -h}, a), c + rot({w, h}, a), c + rot({-w, h}, a)};
}

/// A rectangle seen in perspective: corners moved by up to 20% of the size, kept convex.
Poly perspectiveQuad(std::mt19937& rng) {
  Poly q = rectangle(rng, 80, 200, 60, 150);
  const double s = 0.2 * (q[0] - q[2]).norm() / 2;
  for (auto& p : q) p += Eigen::Vector2d(uniform(rng, -s, s), uniform(rng, -s, s));
  return q;
}

Poly triangle(std::mt19937& rng) {
  const Eigen::Vector2d c(150, 150);
  const double a = uniform(rng, -M_PI, M_PI);
  Poly t;
  for (int k = 0; k < 3; ++k)
    t.push_back(c + rot({uniform(rng, 50, 110), 0}, a + k * 2.0944 + uniform(rng, -0.3, 0.3)));
  return t;
}

Poly lShape(std::mt19937& rng) {
  const double w = uniform(rng, 80, 160), h = uniform(rng, 80, 160), t = uniform(rng, 0.3, 0.5),
               a = uniform(rng, -3, 3);
  const Eigen::Vector2d c(150, 150);
  const Poly base = {{-w / 2, -h / 2},        {w / 2, -h / 2},
                     {w / 2, -h / 2 + t * h}, {-w / 2 + t * w, -h / 2 + t * h},
                     {-w / 2 + t * w, h / 2}, {-w / 2, h / 2}};
  Poly out;
  for (const auto& p : base) out.push_back(c + rot(p, a));
  return out;
}

/// The silhouette of a box showing two or three faces: the convex hull of c +- u +- v +- w for
/// three 2D edge vectors of comparable length, a hexagon.
Poly boxSilhouette(std::mt19937& rng) {
  const double a0 = uniform(rng, -M_PI, M_PI);
  const Eigen::Vector2d u = rot({uniform(rng, 35, 70), 0}, a0),
                        v = rot({uniform(rng, 35, 70), 0}, a0 + uniform(rng, 1.6, 2.4)),
                        w = rot({uniform(rng, 30, 60), 0}, a0 + uniform(rng, 3.6, 4.4));
  // Hexagon vertices in order: the six sign patterns that are extreme.
  const Eigen::Vector2d c(150, 150);
  std::vector<Eigen::Vector2d> pts;
  for (int k = 0; k < 8; ++k) pts.push_back(c + ((k & 1) ? u : -u) + ((k & 2) ? v : -v) + ((k & 4) ? w : -w));
  // Convex hull (gift wrapping, tiny input).
  Poly hull;
  int start = 0;
  for (int k = 1; k < 8; ++k)
    if (pts[k](0) < pts[start](0)) start = k;
  int p = start;
  do {
    hull.push_back(pts[p]);
    int q = (p + 1) % 8;
    for (int r = 0; r < 8; ++r) {
      const Eigen::Vector2d d1 = pts[q] - pts[p], d2 = pts[r] - pts[p];
      if (d1(0) * d2(1) - d1(1) * d2(0) < 0) q = r;
    }
    p = q;
  } while (p != start && hull.size() < 9);
  return hull;
}

BinaryMask blob(std::mt19937& rng) {
  BinaryMask m(300, 300);
  for (int k = 0; k < 3; ++k) {
    const Ellipse e({uniform(rng, 110, 190), uniform(rng, 110, 190)}, {uniform(rng, 25, 55), uniform(rng, 25, 55)}, 0);
    const BinaryMask part = test::rasterEllipse(e, 300, 300);
    for (size_t i = 0; i < m.data.size(); ++i) m.data[i] |= part.data[i];
  }
  return m;
}

}  // namespace

// The labelled set the thresholds of RegularMaskOptions were chosen on, with boundary noise.
TEST(RegularMask, LabelledSetIsClassifiedAt95Percent) {
  std::mt19937 rng(101);
  int correct = 0, total = 0;
  std::map<std::string, std::pair<int, int>> per_kind;  // correct, total
  auto check = [&](const std::string& kind, BinaryMask m, bool regular) {
    test::addBoundaryNoise(m, rng, 0.3);
    const RegularVerdict v = testRegularMask(encodeMask(m));
    const bool ok = v.regular == regular;
    correct += ok;
    ++total;
    per_kind[kind].first += ok;
    per_kind[kind].second += 1;
  };
  for (int i = 0; i < 40; ++i) {
    check("rectangle", test::rasterPolygon(rectangle(rng, 40, 200, 30, 150), 300, 300), true);
    check("perspective quad", test::rasterPolygon(perspectiveQuad(rng), 300, 300), true);
    check("thin box face-on", test::rasterPolygon(rectangle(rng, 120, 250, 10, 20), 300, 300), true);
    check("ellipse",
          test::rasterEllipse(Ellipse({150, 150}, {uniform(rng, 20, 120), uniform(rng, 15, 90)}, uniform(rng, -3, 3)),
                              300, 300),
          false);
    check("triangle", test::rasterPolygon(triangle(rng), 300, 300), false);
    check("L-shape", test::rasterPolygon(lShape(rng), 300, 300), false);
    check("box silhouette", test::rasterPolygon(boxSilhouette(rng), 300, 300), false);
    check("blob", blob(rng), false);
  }
  std::string report;
  for (const auto& [kind, ct] : per_kind)
    report += kind + " " + std::to_string(ct.first) + "/" + std::to_string(ct.second) + "; ";
  RecordProperty("per_kind", report);
  EXPECT_GE(correct, 0.95 * total) << report;
}

// The outline test, from the runs, against the simulator's truth: the same rule on the contour
// OpenCV traces (sim::outlineIsConvexQuadrilateral), on noise-free shapes of every kind.
TEST(RegularMask, OutlineTestAgreesWithTheTracedContour) {
  std::mt19937 rng(7);
  std::map<std::string, std::array<int, 3>> counts;  // kind -> agreeing, regular by ours, total
  int agreeing = 0, total = 0;
  auto check = [&](const std::string& kind, const BinaryMask& m) {
    const RleMask rle = encodeMask(m);
    bool convex = false;
    const bool ours = outlineVertices(rle, 0.02, &convex) == 4 && convex;
    const bool ok = ours == sim::outlineIsConvexQuadrilateral(rle);
    agreeing += ok, ++total;
    counts[kind][0] += ok, counts[kind][1] += ours, counts[kind][2] += 1;
  };
  for (int i = 0; i < 40; ++i) {
    check("rectangle", test::rasterPolygon(rectangle(rng, 40, 200, 30, 150), 300, 300));
    check("perspective quad", test::rasterPolygon(perspectiveQuad(rng), 300, 300));
    check("box silhouette", test::rasterPolygon(boxSilhouette(rng), 300, 300));
    check("triangle", test::rasterPolygon(triangle(rng), 300, 300));
    check("L-shape", test::rasterPolygon(lShape(rng), 300, 300));
    check("blob", blob(rng));
  }
  std::string report;
  for (const auto& [kind, c] : counts)
    report += kind + " agree " + std::to_string(c[0]) + " regular " + std::to_string(c[1]) + " of " +
              std::to_string(c[2]) + "; ";
  RecordProperty("per_kind", report);
  EXPECT_GE(agreeing, 0.95 * total) << report;
  // Both accept one face of a box and turn down the other kinds.
  EXPECT_GE(counts["rectangle"][1], 38) << report;
  EXPECT_LE(counts["box silhouette"][1] + counts["triangle"][1] + counts["L-shape"][1] + counts["blob"][1], 8)
      << report;
  // Degenerate input.
  bool convex = true;
  EXPECT_EQ(outlineVertices(RleMask{}, 0.02, &convex), 0);
  EXPECT_FALSE(convex);
}

// A box seen with a sliver of a second face: its four-corner quadrilateral describes the mask
// (quadrilateral test) but its outline keeps a fifth vertex beyond 2% of its length (outline
// test), so it is not the paper's regular object. The paper policy keeps its box; the default
// fits the quadrilateral's ellipse.
TEST(RegularMask, SliverOfASecondFacePassesTheQuadrilateralTestOnly) {
  const int W = 320, H = 240;
  // Face 160 x 100; the second face shows as a 10-pixel sliver along the right side, its far
  // corners shifted down by 14 pixels (perspective).
  const Poly face_and_sliver = {{60, 60}, {220, 60}, {230, 74}, {230, 174}, {220, 160}, {60, 160}};
  const RleMask rle = encodeMask(test::rasterPolygon(face_and_sliver, W, H));
  const RegularVerdict v = testRegularMask(rle);
  EXPECT_TRUE(v.quadrilateral);
  EXPECT_GE(v.outline_vertices, 5);
  EXPECT_FALSE(v.regular);
  // The face alone passes both.
  const Poly face_only = {{60, 60}, {220, 60}, {220, 160}, {60, 160}};
  const RegularVerdict face = testRegularMask(encodeMask(test::rasterPolygon(face_only, W, H)));
  EXPECT_TRUE(face.quadrilateral);
  EXPECT_EQ(face.outline_vertices, 4);
  EXPECT_TRUE(face.regular);

  Detection d;
  d.category_id = 62;
  d.bbox = rleMoments(rle)->bounds;
  d.mask = rle;
  ObserveOptions paper;
  paper.policy = ObservationPolicy::Paper;
  const ObserveResult by_paper = observeDetection(d, W, H, paper);
  EXPECT_EQ(by_paper.observation->source, EllipseSource::Box);
  EXPECT_EQ(by_paper.observation->regular, std::optional<bool>(false));
  const ObserveResult by_default = observeDetection(d, W, H);
  EXPECT_EQ(by_default.observation->source, EllipseSource::Mask);
  EXPECT_EQ(by_default.observation->regular, std::optional<bool>(false));
  const std::optional<Ellipse> quad_fit = fitMaskEllipse(rle, MaskFitMethod::Quadrilateral, &v);
  ASSERT_TRUE(quad_fit);
  EXPECT_LT(wasserstein2(by_default.observation->ellipse, *quad_fit), 1e-9);
}

TEST(RegularMask, DiagnosticsOfARectangle) {
  const BinaryMask m = test::rasterPolygon({{50, 40}, {150, 40}, {150, 100}, {50, 100}}, 200, 200);
  const RegularVerdict v = testRegularMask(encodeMask(m));
  EXPECT_TRUE(v.regular);
  EXPECT_EQ(v.quad_vertices, 4);
  EXPECT_NEAR(v.fill, 1.0, 0.02);
  EXPECT_NEAR(v.solidity, 1.0, 0.02);
  EXPECT_NEAR(v.max_corner_angle_deg, 90.0, 1.0);
  // Corners on the mask's outer pixel edges.
  const Box b = rleMoments(encodeMask(m))->bounds;
  for (const auto& c : v.corners) {
    EXPECT_NEAR(std::min(std::abs(c(0) - b.x1), std::abs(c(0) - b.x2)), 0.0, 0.01);
    EXPECT_NEAR(std::min(std::abs(c(1) - b.y1), std::abs(c(1) - b.y2)), 0.0, 0.01);
  }
  EXPECT_FALSE(v.touches_border);
}

TEST(RegularMask, RealLabelmeMasks) {
  // The quadrilateral test on the 12 real instances, in file order, with the diagnostics that
  // decide it (solidity / fill / core fill). Passed: the bottle (0.95 / 1.11 / 1.03), the
  // chair-labelled wide mask of 2011_000006 (0.91 / 1.02 / 0.96), a small distant person (0.95 /
  // 1.08 / 1.03), the bus cut by the left image border (0.95 / 1.13 / 0.99) and the car (0.96 /
  // 1.06 / 1.01): four-sided silhouettes. Failed: the other people (core fill 0.73-0.94: arms
  // and legs leave the quadrilateral's core empty), the sofa (0.26 solidity) and the large bus
  // showing two faces (fill 1.15, core 0.93). None is the paper's regular object: the outlines
  // of the five keep 6, 7, 5, 7 and 6 vertices within 2% of their length (a bottle, a chair, a
  // person, a bus and a car are not four-sided), and the set holds no box-like object.
  const std::vector<bool> expected = {false, false, true, false, false, false, true, true, false, false, true, true};
  const auto frames = io::readDetections(test::dataPath("labelme_masks/detections.json"));
  std::vector<bool> quadrilaterals;
  std::vector<int> outline_vertices;
  for (const auto& f : frames)
    for (const auto& d : f.detections) {
      const RegularVerdict v = testRegularMask(*d.mask);
      EXPECT_FALSE(v.regular);
      quadrilaterals.push_back(v.quadrilateral);
      if (v.quadrilateral) outline_vertices.push_back(v.outline_vertices);
    }
  EXPECT_EQ(quadrilaterals, expected);
  EXPECT_EQ(outline_vertices, std::vector<int>({6, 7, 5, 7, 6}));
  // The default (solid) policy also fits the masks that fill at least half of their hull: the
  // bus seen on two faces (solidity 0.90) and the five people (0.65-0.82); the sofa (0.26)
  // keeps its box.
  const std::vector<bool> fitted = {true, true, true, true, true, true, true, true, false, true, true, true};
  std::vector<bool> sources;
  for (const auto& f : frames)
    for (const auto& d : f.detections)
      sources.push_back(observeDetection(d, d.mask->width, d.mask->height).observation->source == EllipseSource::Mask);
  EXPECT_EQ(sources, fitted);
}

TEST(Observe, PoliciesAndBadInput) {
  const int W = 300, H = 200;
  Detection d;
  d.category_id = 62;
  d.bbox = Box(49.5, 39.5, 150.5, 100.5);
  d.mask = encodeMask(test::rasterPolygon({{50, 40}, {150, 40}, {150, 100}, {50, 100}}, W, H));
  // Paper: a regular mask is fitted (here the rectangle's inscribed ellipse, = the box's).
  ObserveResult r = observeDetection(d, W, H);
  ASSERT_EQ(r.status, ObserveStatus::Ok);
  EXPECT_EQ(r.observation->source, EllipseSource::Mask);
  EXPECT_EQ(r.observation->regular, std::optional<bool>(true));
  const Box b = rleMoments(*d.mask)->bounds;  // the mask's outer pixel edges
  EXPECT_LT((r.observation->ellipse.center() - b.center()).norm(), 0.05);
  EXPECT_NEAR(r.observation->ellipse.axes()(0), 0.5 * b.width(), 0.05);
  EXPECT_NEAR(r.observation->ellipse.axes()(1), 0.5 * b.height(), 0.05);
  // Bbox policy ignores the mask.
  ObserveOptions bbox;
  bbox.policy = ObservationPolicy::Bbox;
  EXPECT_EQ(observeDetection(d, W, H, bbox).observation->source, EllipseSource::Box);
  // An irregular mask under Paper: the box; under Mask and Solid (it is solid): fitted.
  Detection round = d;
  round.mask = encodeMask(test::rasterEllipse(Ellipse({100, 70}, {40, 25}, 0.3), W, H));
  ObserveOptions paper;
  paper.policy = ObservationPolicy::Paper;
  EXPECT_EQ(observeDetection(round, W, H, paper).observation->source, EllipseSource::Box);
  EXPECT_EQ(observeDetection(round, W, H).observation->source, EllipseSource::Mask);
  ObserveOptions mask;
  mask.policy = ObservationPolicy::Mask;
  const ObserveResult rm = observeDetection(round, W, H, mask);
  EXPECT_EQ(rm.observation->source, EllipseSource::Mask);
  EXPECT_LT(wasserstein2(rm.observation->ellipse, Ellipse({100, 70}, {40, 25}, 0.3)), 1.0);
  // The other fits a host may choose for masks that are not regular: the mask's moments and the
  // direct fit of its outline recover the rasterised ellipse as well.
  for (const MaskFitMethod method : {MaskFitMethod::Moments, MaskFitMethod::Direct}) {
    ObserveOptions chosen = mask;
    chosen.irregular_fit = method;
    const ObserveResult rf = observeDetection(round, W, H, chosen);
    EXPECT_EQ(rf.observation->source, EllipseSource::Mask);
    EXPECT_LT(wasserstein2(rf.observation->ellipse, Ellipse({100, 70}, {40, 25}, 0.3)), 1.0);
    EXPECT_GT(wasserstein2(rf.observation->ellipse, rm.observation->ellipse), 1e-6);  // another fit than the hull's
  }
  // A polygon stands for a mask under Solid (the default) and Mask, and gives the same observation.
  Detection polygon = d;
  polygon.mask.reset();
  polygon.polygon = {{50, 40}, {150, 40}, {150, 100}, {50, 100}};
  for (const ObserveOptions& o : {ObserveOptions(), mask}) {
    const ObserveResult from_mask = observeDetection(d, W, H, o), from_polygon = observeDetection(polygon, W, H, o);
    EXPECT_EQ(from_polygon.observation->source, EllipseSource::Mask);
    EXPECT_EQ(from_polygon.observation->regular, from_mask.observation->regular);
    EXPECT_LT(wasserstein2(from_polygon.observation->ellipse, from_mask.observation->ellipse), 1e-9);
  }
  EXPECT_EQ(observeDetection(polygon, W, H, bbox).observation->source, EllipseSource::Box);
  Detection outside_polygon = polygon;
  outside_polygon.polygon = {{-20, -20}, {-10, -20}, {-10, -10}};
  r = observeDetection(outside_polygon, W, H, mask);
  EXPECT_EQ(r.observation->source, EllipseSource::Box);
  EXPECT_NE(r.note.find("polygon"), std::string::npos);
  // Given.
  ObserveOptions given;
  given.policy = ObservationPolicy::Given;
  EXPECT_EQ(observeDetection(d, W, H, given).status, ObserveStatus::NoEllipse);
  Detection with_ellipse = d;
  with_ellipse.ellipse = Ellipse({1, 2}, {3, 4}, 0.5);
  EXPECT_EQ(observeDetection(with_ellipse, W, H, given).observation->ellipse.center(), Eigen::Vector2d(1, 2));

  // Bad input: statuses and notes, never a crash.
  Detection empty = d;
  empty.mask = encodeMask(BinaryMask(H, W));
  r = observeDetection(empty, W, H);
  EXPECT_EQ(r.observation->source, EllipseSource::Box);
  EXPECT_NE(r.note.find("empty"), std::string::npos);
  Detection one = d;
  BinaryMask single(H, W);
  single.at(10, 10) = 1;
  one.mask = encodeMask(single);
  r = observeDetection(one, W, H, mask);
  ASSERT_TRUE(r.observation.has_value());
  EXPECT_TRUE(r.observation->ellipse.isValid());
  Detection wrong_size = d;
  wrong_size.mask = encodeMask(BinaryMask(H + 1, W));
  r = observeDetection(wrong_size, W, H);
  EXPECT_EQ(r.observation->source, EllipseSource::Box);
  EXPECT_NE(r.note.find("differs from the image"), std::string::npos);
  Detection outside = d;
  outside.bbox = Box(400, 300, 450, 350);
  EXPECT_EQ(observeDetection(outside, W, H).status, ObserveStatus::InvalidBox);
  Detection nan_box = d;
  nan_box.bbox = Box(std::nan(""), 1, 2, 3);
  EXPECT_EQ(observeDetection(nan_box, W, H).status, ObserveStatus::InvalidBox);
  Detection flat = d;
  flat.bbox = Box(10, 10, 10, 20);
  EXPECT_EQ(observeDetection(flat, W, H).status, ObserveStatus::InvalidBox);
  // A frame's detections: those without an observation are left out, the others kept in order.
  Detection later = d;
  later.category_id = d.category_id + 1;
  const std::vector<Observation> frame = observeDetections({d, outside, nan_box, later, flat}, W, H);
  ASSERT_EQ(frame.size(), 2u);
  EXPECT_EQ(frame[0].category, d.category_id);
  EXPECT_EQ(frame[1].category, later.category_id);
  // Options out of range: a status naming the field, no observation.
  ObserveOptions nan_border;
  nan_border.border_px = NAN;
  r = observeDetection(d, W, H, nan_border);
  EXPECT_EQ(r.status, ObserveStatus::InvalidOptions);
  EXPECT_FALSE(r.observation.has_value());
  EXPECT_NE(r.note.find("border_px"), std::string::npos);
  ObserveOptions crossed = mask;
  crossed.regular.min_fill = 2.0;  // above max_fill
  EXPECT_NE(observeDetection(d, W, H, crossed).note.find("regular.min_fill"), std::string::npos);
  // Truncation: a box at the image border is flagged.
  Detection edge = d;
  edge.bbox = Box(-0.5, 10, 40, 60);
  edge.mask.reset();
  EXPECT_TRUE(observeDetection(edge, W, H).observation->truncated);
}

TEST(Observe, SolidPolicyFitsTheHullOfConvexSilhouettesOnly) {
  const int W = 300, H = 200;
  // A cuboid seen on a corner: a hexagonal silhouette, not a quadrilateral, and solid.
  const std::vector<Eigen::Vector2d> hexagon = {{60, 60}, {120, 40}, {190, 55}, {200, 120}, {140, 150}, {70, 130}};
  Detection box_like;
  box_like.category_id = 73;
  box_like.bbox = Box(59.5, 39.5, 200.5, 150.5);
  box_like.mask = encodeMask(test::rasterPolygon(hexagon, W, H));
  const RegularVerdict hex = testRegularMask(*box_like.mask);
  ASSERT_FALSE(hex.regular);
  ASSERT_GT(hex.solidity, 0.95);
  const ObserveResult solid = observeDetection(box_like, W, H);  // Solid is the default
  ASSERT_EQ(solid.status, ObserveStatus::Ok);
  EXPECT_EQ(solid.observation->source, EllipseSource::Mask);
  EXPECT_EQ(solid.observation->regular, std::optional<bool>(false));
  const std::optional<Ellipse> hull = fitMaskEllipse(*box_like.mask, MaskFitMethod::Hull, &hex);
  ASSERT_TRUE(hull.has_value());
  EXPECT_LT(wasserstein2(solid.observation->ellipse, *hull), 1e-9);
  ObserveOptions paper;
  paper.policy = ObservationPolicy::Paper;
  EXPECT_EQ(observeDetection(box_like, W, H, paper).observation->source, EllipseSource::Box);

  // A chair-like outline (a seat and a back on thin legs) fills little of its hull: the box.
  const std::vector<Eigen::Vector2d> chair = {{80, 20},  {110, 20},  {110, 100}, {190, 100}, {190, 180}, {182, 180},
                                              {182, 115}, {108, 115}, {108, 180}, {100, 180}, {100, 115}, {80, 115}};
  Detection composite = box_like;
  composite.bbox = Box(79.5, 19.5, 190.5, 180.5);
  composite.mask = encodeMask(test::rasterPolygon(chair, W, H));
  const RegularVerdict legs = testRegularMask(*composite.mask);
  ASSERT_LT(legs.solidity, ObserveOptions().solid_min_solidity);
  EXPECT_EQ(observeDetection(composite, W, H).observation->source, EllipseSource::Box);

  // The threshold is an option; 1 keeps the box for every non-regular mask, as Paper does.
  ObserveOptions strict;
  strict.solid_min_solidity = 1.0;
  EXPECT_EQ(observeDetection(box_like, W, H, strict).observation->source, EllipseSource::Box);
  ObserveOptions lax;
  lax.solid_min_solidity = 0.0;
  EXPECT_EQ(observeDetection(composite, W, H, lax).observation->source, EllipseSource::Mask);
  ObserveOptions bad;
  bad.solid_min_solidity = 1.5;
  const ObserveResult refused = observeDetection(box_like, W, H, bad);
  EXPECT_EQ(refused.status, ObserveStatus::InvalidOptions);
  EXPECT_NE(refused.note.find("solid_min_solidity"), std::string::npos);
  ObservationPolicy parsed;
  ASSERT_TRUE(parseObservationPolicy("solid", &parsed));
  EXPECT_EQ(parsed, ObservationPolicy::Solid);
  EXPECT_STREQ(toString(ObservationPolicy::Solid), "solid");
}

TEST(Observe, SolidPolicyFitsTheHullOfAChairSeenWhole) {
  // A chair (seat, back and four legs, each a cuboid) seen whole from around it: its mask fills
  // half to four fifths of its hull, which spans about the silhouette of the chair's cuboid.
  // The hull fit then lands nearer the projection of the ellipsoid inscribed in that cuboid (the
  // truth, computed here by projecting it) than the box-inscribed ellipse does.
  const Intrinsics K(300.0, 300.0, 159.5, 119.5, 320, 240);
  const double w = 0.22, d = 0.22, seat = 0.45, back = 0.45, leg = 0.02;
  const Eigen::Vector3d half(w, d, (seat + back) / 2);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> parts = {  // centre, half-extents
      {{0, 0, -half(2) + seat}, {w, d, 0.02}},
      {{0, d - 0.02, -half(2) + seat + back / 2}, {w, 0.02, back / 2}}};
  for (int k = 0; k < 4; ++k)
    parts.push_back({{(k & 1 ? 1 : -1) * (w - leg), (k & 2 ? 1 : -1) * (d - leg), -half(2) + seat / 2},
                     {leg, leg, seat / 2}});
  std::vector<double> hull_errors, box_errors;
  int gappy = 0;
  for (int view = 0; view < 12; ++view) {
    const double azimuth = 2 * M_PI * view / 12 + 0.3, elevation = 0.25 + 0.02 * (view % 4), distance = 2.4;
    const Eigen::Vector3d eye =
        distance * Eigen::Vector3d(std::cos(azimuth) * std::cos(elevation), std::sin(azimuth) * std::cos(elevation),
                                   std::sin(elevation));
    const Pose pose = Pose::lookAt(eye, Eigen::Vector3d::Zero());
    BinaryMask mask(K.height, K.width);
    for (const auto& [centre, extent] : parts) {
      Poly corners;
      for (int k = 0; k < 8; ++k)
        corners.push_back(K.project(pose.transform(
            centre + Eigen::Vector3d((k & 1 ? 1 : -1) * extent(0), (k & 2 ? 1 : -1) * extent(1),
                                     (k & 4 ? 1 : -1) * extent(2)))));
      test::addConvexHull(corners, mask);
    }
    Detection chair;
    chair.category_id = 56;
    chair.mask = encodeMask(mask);
    chair.bbox = rleMoments(*chair.mask)->bounds;
    const RegularVerdict verdict = testRegularMask(*chair.mask);
    ASSERT_FALSE(verdict.regular);
    if (verdict.solidity >= 0.8 || verdict.solidity < 0.5) continue;
    ++gappy;
    const ObserveResult fitted = observeDetection(chair, K.width, K.height);  // the default: solid
    ASSERT_EQ(fitted.status, ObserveStatus::Ok);
    EXPECT_EQ(fitted.observation->source, EllipseSource::Mask);
    const Projection truth = project(Ellipsoid(Eigen::Vector3d::Zero(), half, Eigen::Matrix3d::Identity()), K, pose);
    ASSERT_TRUE(truth.ok());
    const double scale = std::sqrt(truth.ellipse.axes().prod());
    hull_errors.push_back(wasserstein2(fitted.observation->ellipse, truth.ellipse) / scale);
    box_errors.push_back(wasserstein2(*Ellipse::inscribedInBox(chair.bbox), truth.ellipse) / scale);
  }
  ASSERT_GE(gappy, 6);  // most views: the legs and the gap under the seat leave a fifth to a half empty
  EXPECT_LT(median(hull_errors), 0.8 * median(box_errors));
}
