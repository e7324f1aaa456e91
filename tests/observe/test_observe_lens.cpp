// Observations of a raw image through a distorted lens (ObserveOptions::lens): made in the raw
// image, then moved to the pinhole image.
#include <gtest/gtest.h>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/mask.hpp"
#include "ellreloc/observe/observe.hpp"
#include "fixtures/mask_shapes.hpp"

using namespace ellreloc;

namespace {

// TUM fr2's factory calibration: the raw images of its Kinect are not undistorted.
const Intrinsics kFr2(520.90862, 521.007327, 325.141442, 249.701764, 640, 480);
const Lens kFr2Lens{kFr2, {0.231222, -0.784899, -0.003257, -0.000105, 0.917205}};

ObserveOptions withLens(const Lens& lens, ObservationPolicy policy = ObservationPolicy::Solid) {
  ObserveOptions o;
  o.policy = policy;
  o.lens = lens;
  return o;
}

}  // namespace

TEST(ObserveLens, ABoxObservationIsInscribedInTheUndistortedBox) {
  Detection d;
  d.category_id = 62;
  d.bbox = Box(30.0, 20.0, 180.0, 140.0);
  const ObserveResult r = observeDetection(d, 640, 480, withLens(kFr2Lens));
  ASSERT_EQ(r.status, ObserveStatus::Ok) << r.note;
  const Box expected = *kFr2Lens.undistortBox(d.bbox);
  EXPECT_NEAR(r.observation->box.x1, expected.x1, 1e-12);
  EXPECT_NEAR(r.observation->box.y2, expected.y2, 1e-12);
  EXPECT_GT(std::abs(r.observation->box.x1 - d.bbox.x1), 3.0);  // the lens moved it
  EXPECT_LT(wasserstein2(r.observation->ellipse, *Ellipse::inscribedInBox(expected)), 1e-12);
  EXPECT_EQ(r.observation->source, EllipseSource::Box);
}

// A box the raw image's border cuts stays flagged though the lens pulls it inwards: the object
// is cut in the raw image, whatever its pinhole image.
TEST(ObserveLens, TheBorderTestIsTheRawImages) {
  Detection d;
  d.bbox = Box(-0.5, 100.0, 90.0, 200.0);
  const ObserveResult r = observeDetection(d, 640, 480, withLens(kFr2Lens));
  ASSERT_TRUE(r.observation);
  EXPECT_TRUE(r.observation->truncated);
  EXPECT_GT(r.observation->box.x1, 1.5);  // inside the border once undistorted
}

TEST(ObserveLens, AMaskIsFittedInTheRawImageAndItsEllipseUndistorted) {
  Detection d;
  d.category_id = 41;
  const Ellipse drawn({120.0, 110.0}, {50.0, 30.0}, 0.5);
  d.mask = encodeMask(test::rasterEllipse(drawn, 640, 480));
  d.bbox = *maskBox(*d.mask);
  const ObserveResult raw = observeDetection(d, 640, 480);
  const ObserveResult r = observeDetection(d, 640, 480, withLens(kFr2Lens));
  ASSERT_TRUE(raw.observation && r.observation);
  EXPECT_EQ(r.observation->source, EllipseSource::Mask);
  EXPECT_EQ(r.observation->regular, raw.observation->regular);
  EXPECT_LT(wasserstein2(r.observation->ellipse, *kFr2Lens.undistortEllipse(raw.observation->ellipse)), 1e-12);
  EXPECT_GT(wasserstein2(r.observation->ellipse, raw.observation->ellipse), 2.0);
}

TEST(ObserveLens, NoDistortionGivesTheSameObservation) {
  Detection d;
  d.bbox = Box(200.0, 150.0, 320.0, 260.0);
  d.mask = encodeMask(test::rasterEllipse(Ellipse({260.0, 205.0}, {55.0, 50.0}, 0.0), 640, 480));
  const ObserveResult plain = observeDetection(d, 640, 480);
  const ObserveResult r = observeDetection(d, 640, 480, withLens(Lens{kFr2, {}}));
  ASSERT_TRUE(plain.observation && r.observation);
  EXPECT_LT(wasserstein2(r.observation->ellipse, plain.observation->ellipse), 1e-12);
  EXPECT_NEAR(r.observation->box.x2, plain.observation->box.x2, 1e-9);
}

TEST(ObserveLens, ALensOfAnotherImageOrThatFoldsIsRefused) {
  Detection d;
  d.bbox = Box(200.0, 150.0, 320.0, 260.0);
  ObserveResult r = observeDetection(d, 320, 240, withLens(kFr2Lens));
  EXPECT_EQ(r.status, ObserveStatus::InvalidOptions);
  EXPECT_NE(r.note.find("640x480"), std::string::npos) << r.note;
  r = observeDetection(d, 640, 480, withLens(Lens{kFr2, {-0.9, 0, 0, 0, 0}}));
  EXPECT_EQ(r.status, ObserveStatus::InvalidOptions);
  EXPECT_NE(r.note.find("lens"), std::string::npos) << r.note;
}
