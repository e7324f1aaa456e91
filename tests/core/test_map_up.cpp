#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "ellreloc/core/map_up.hpp"

using namespace ellreloc;

namespace {

// COCO ids of an office: chair, tv, keyboard, cup, book, mouse, bottle, potted plant.
const std::vector<int> kOfficeCategories = {56, 62, 66, 41, 73, 64, 39, 58};

struct Room {
  ObjectMap map;
  Eigen::Vector3d up;  // in the map frame
};

// `count` objects of the office categories at their usual heights (+- 10 cm) above a floor of
// `length` x `depth` metres, seen in a map frame turned and shifted at random.
Room officeRoom(std::mt19937& rng, int count, double length, double depth) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::normal_distribution<double> jitter(0.0, 0.1);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const Eigen::Matrix3d turn =
      Eigen::Quaterniond(gauss(rng), gauss(rng), gauss(rng), gauss(rng)).normalized().toRotationMatrix();
  const Eigen::Vector3d shift(u01(rng) * 10 - 5, u01(rng) * 10 - 5, u01(rng) * 10 - 5);
  Room room;
  room.up = turn * Eigen::Vector3d::UnitZ();
  for (int i = 0; i < count; ++i) {
    MapObject o;
    o.id = i;
    o.category = kOfficeCategories[static_cast<size_t>(i) % kOfficeCategories.size()];
    const Eigen::Vector3d in_room(u01(rng) * length, u01(rng) * depth, typicalCentreHeight(o.category) + jitter(rng));
    o.ellipsoid = Ellipsoid(turn * in_room + shift, {0.1, 0.1, 0.1}, turn);
    room.map.objects.push_back(o);
  }
  return room;
}

double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
}

}  // namespace

TEST(MapUp, TypicalHeightsPlaceDeskObjectsAboveChairsAndKnowNoCars) {
  EXPECT_GT(typicalCentreHeight(62), typicalCentreHeight(66));  // a monitor above its keyboard
  EXPECT_GT(typicalCentreHeight(66), typicalCentreHeight(56));  // a keyboard above a chair's centre
  EXPECT_TRUE(std::isnan(typicalCentreHeight(2)));              // car
  EXPECT_TRUE(std::isnan(typicalCentreHeight(80)));
  EXPECT_TRUE(std::isnan(typicalCentreHeight(-1)));
  for (int id = 0; id < 80; ++id) {
    const double h = typicalCentreHeight(id);
    if (std::isfinite(h)) EXPECT_TRUE(h > 0.0 && h < 2.5) << id;
  }
}

// Objects spread over a 5 x 4 m floor: the up is found, with its sign, in any map frame; within
// a few degrees (30 objects whose heights vary by 10 cm tilt the least spread a little).
TEST(MapUp, FindsTheVerticalAndItsSignInAnyFrame) {
  std::mt19937 rng(3);
  std::vector<double> errors;
  const int rooms = 200;
  for (int trial = 0; trial < rooms; ++trial) {
    const Room room = officeRoom(rng, 30, 5.0, 4.0);
    const auto found = estimateMapUp(room.map);
    if (!found) continue;
    errors.push_back(angleDeg(found->up, room.up));
    EXPECT_LT(errors.back(), 10.0) << "trial " << trial;
    EXPECT_NEAR(found->up.norm(), 1.0, 1e-12);
    EXPECT_EQ(found->objects, 30);
    EXPECT_GE(found->t, 2.5);
  }
  EXPECT_GE(errors.size(), rooms * 0.98);
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  EXPECT_LT(errors[errors.size() / 2], 3.0);
}

// The sign comes from what the objects are: the same room upside down (each object's height
// negated) gives the opposite up.
TEST(MapUp, TheSignFollowsTheCategoriesHeights) {
  std::mt19937 rng(4);
  Room room = officeRoom(rng, 30, 5.0, 4.0);
  const auto found = estimateMapUp(room.map);
  ASSERT_TRUE(found);
  for (MapObject& o : room.map.objects) {  // mirror each centre through the plane normal to up
    const Eigen::Vector3d c = o.ellipsoid.center();
    o.ellipsoid = Ellipsoid(c - 2.0 * room.up * room.up.dot(c), o.ellipsoid.axes(), o.ellipsoid.rotation());
  }
  const auto mirrored = estimateMapUp(room.map);
  ASSERT_TRUE(mirrored);
  EXPECT_LT(angleDeg(mirrored->up, -room.up), 5.0);
}

// No estimate without clear evidence: objects along one wall (the least spread is horizontal),
// too few objects of known categories, a map of objects with no usual height, an empty map.
TEST(MapUp, NoEstimateWithoutClearEvidence) {
  std::mt19937 rng(5);
  EXPECT_FALSE(estimateMapUp(officeRoom(rng, 30, 5.0, 0.1).map));  // a 5 m shelf 10 cm deep
  EXPECT_FALSE(estimateMapUp(officeRoom(rng, 7, 5.0, 4.0).map));
  Room cars = officeRoom(rng, 30, 5.0, 4.0);
  for (MapObject& o : cars.map.objects) o.category = 2;
  EXPECT_FALSE(estimateMapUp(cars.map));
  EXPECT_FALSE(estimateMapUp(ObjectMap{}));
}

// Categories that say nothing of the heights (labels dealt at random to the objects of a room)
// rarely give an estimate: the t statistic's chance level.
TEST(MapUp, LabelsUnrelatedToHeightRarelyGiveAnEstimate) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<size_t> any(0, kOfficeCategories.size() - 1);
  int given = 0;
  const int rooms = 300;
  for (int trial = 0; trial < rooms; ++trial) {
    Room room = officeRoom(rng, 30, 5.0, 4.0);
    for (MapObject& o : room.map.objects) o.category = kOfficeCategories[any(rng)];
    given += estimateMapUp(room.map).has_value();
  }
  EXPECT_LE(given, rooms / 20);  // |t| >= 2.5 by chance: about 1.6% of rooms
}

// Objects a relocalizer cannot use do not count.
TEST(MapUp, UnusableObjectsDoNotCount) {
  std::mt19937 rng(6);
  Room room = officeRoom(rng, 30, 5.0, 4.0);
  MapObject bad;
  bad.category = 62;
  bad.ellipsoid = Ellipsoid(Eigen::Vector3d(NAN, 0.0, 0.0), {0.1, 0.1, 0.1}, Eigen::Matrix3d::Identity());
  room.map.objects.push_back(bad);
  const auto found = estimateMapUp(room.map);
  ASSERT_TRUE(found);
  EXPECT_EQ(found->objects, 30);
  EXPECT_TRUE(found->up.allFinite());
}
