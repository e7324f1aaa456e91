#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "ellreloc/error.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/map.hpp"
#include "fixtures/data_dir.hpp"
#include "fixtures/random_geometry.hpp"
#include "fixtures/temp_dir.hpp"

using namespace ellreloc;

TEST(MapIo, ReadsTheFr2MapAndItsDualQuadricsAgree) {
  const std::string path = test::dataPath("tum_fr2_desk/map.json");
  const ObjectMap map = io::readMap(path);
  ASSERT_EQ(map.objects.size(), 47u);
  EXPECT_EQ(map.objects[0].category, 66);
  EXPECT_EQ(map.objects[0].label, "keyboard");
  // The file stores each object twice: as centre/axes/rotation and as a float32 dual quadric.
  const auto j = nlohmann::json::parse(io::readTextFile(path));
  for (size_t i = 0; i < map.objects.size(); ++i) {
    const Ellipsoid& e = map.objects[i].ellipsoid;
    EXPECT_TRUE(e.isValid());
    Eigen::Matrix4d Q;
    for (int k = 0; k < 16; ++k)
      Q(k / 4, k % 4) = j["objects"][i]["dual_quadric"][static_cast<size_t>(k)].get<double>();
    const auto from_q = Ellipsoid::fromDualQuadric(Q);
    ASSERT_TRUE(from_q.has_value());
    EXPECT_LT((from_q->center() - e.center()).norm(), 1e-5);
    EXPECT_LT((from_q->shapeMatrix() - e.shapeMatrix()).norm(), 1e-5 * e.shapeMatrix().norm() + 1e-7);
  }
}

TEST(MapIo, JsonRoundTripAndDualQuadricForm) {
  std::mt19937 rng(41);
  ObjectMap map;
  for (int i = 0; i < 20; ++i) map.objects.push_back({i * 3, i % 5, i % 2 ? "cup" : "", test::randomEllipsoid(rng)});
  map.points = {{0.1, 0.2, 0.3}, {-1, 2, 5}};
  test::TempDir dir;
  io::writeMap(dir.path("map.json"), map);
  const ObjectMap back = io::readMap(dir.path("map.json"));
  ASSERT_EQ(back.objects.size(), map.objects.size());
  ASSERT_EQ(back.points.size(), 2u);
  EXPECT_EQ(back.points[1], map.points[1]);
  for (size_t i = 0; i < map.objects.size(); ++i) {
    EXPECT_EQ(back.objects[i].id, map.objects[i].id);
    EXPECT_EQ(back.objects[i].category, map.objects[i].category);
    EXPECT_EQ(back.objects[i].label, map.objects[i].label);
    EXPECT_LT((back.objects[i].ellipsoid.dualQuadric() - map.objects[i].ellipsoid.dualQuadric()).norm(), 1e-12);
  }
  // Objects given only as a dual quadric, at gtsam's +1 normalisation.
  nlohmann::json j = {{"objects", nlohmann::json::array()}};
  for (const MapObject& o : map.objects) {
    const Eigen::Matrix4d Q = -o.ellipsoid.dualQuadric();
    std::vector<double> q;
    for (int k = 0; k < 16; ++k) q.push_back(Q(k / 4, k % 4));
    j["objects"].push_back({{"id", o.id}, {"category", o.category}, {"dual_quadric", q}});
  }
  const ObjectMap from_q = io::parseMapJson(j.dump(), "inline");
  for (size_t i = 0; i < map.objects.size(); ++i)
    EXPECT_LT((from_q.objects[i].ellipsoid.shapeMatrix() - map.objects[i].ellipsoid.shapeMatrix()).norm(), 1e-12);
  EXPECT_FALSE(back.camera_envelope);  // none written, none read
}

TEST(MapIo, TheCameraEnvelopeRoundTrips) {
  std::mt19937 rng(42);
  ObjectMap map;
  map.objects.push_back({1, 41, "cup", test::randomEllipsoid(rng)});
  CameraEnvelope e;
  e.up = Eigen::Vector3d(0.0, 0.6, 0.8);
  e.min_height = 0.25, e.max_height = 2.5, e.min_tilt_deg = 3.0, e.max_tilt_deg = 61.5;
  map.camera_envelope = e;
  test::TempDir dir;
  io::writeMap(dir.path("map.json"), map);
  const ObjectMap back = io::readMap(dir.path("map.json"));
  ASSERT_TRUE(back.camera_envelope);
  EXPECT_EQ(back.camera_envelope->up, e.up);
  EXPECT_EQ(back.camera_envelope->min_height, 0.25);
  EXPECT_EQ(back.camera_envelope->max_height, 2.5);
  EXPECT_EQ(back.camera_envelope->min_tilt_deg, 3.0);
  EXPECT_EQ(back.camera_envelope->max_tilt_deg, 61.5);
  map.camera_envelope->max_height = 0.0;  // below min: not written, no file left
  EXPECT_THROW(io::writeMap(dir.path("bad.json"), map), Error);
  EXPECT_FALSE(std::ifstream(dir.path("bad.json")).good());
}

// A map in a unit other than the metre says so (unit_metres), and the bounds on semi-axes are
// checked in metres: a 0.5 mm semi-axis of a map in units of 4 m is 2 mm, a 3-unit one 12 m.
TEST(MapIo, TheMapsUnitRoundTripsAndTheBoundsAreInMetres) {
  test::TempDir dir;
  ObjectMap map;
  map.objects.push_back({1, 41, "cup", Ellipsoid({0, 0, 1}, {0.0005, 0.02, 0.03}, Eigen::Matrix3d::Identity())});
  map.objects.push_back({2, 62, "tv", Ellipsoid({1, 0, 1}, {0.1, 3.0, 0.2}, Eigen::Matrix3d::Identity())});
  map.unit_metres = 4.0;
  io::writeMap(dir.path("map.json"), map);
  EXPECT_EQ(nlohmann::json::parse(io::readTextFile(dir.path("map.json")))["unit_metres"], 4.0);
  std::vector<std::string> warnings;
  const ObjectMap back = io::readMap(dir.path("map.json"), &warnings);
  EXPECT_EQ(back.unit_metres, 4.0);
  ASSERT_EQ(back.objects.size(), 1u);
  EXPECT_EQ(back.objects[0].id, 1);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("object 2 left out: semi-axis 3 (12 m) is above 10 m"), std::string::npos) << warnings[0];
  // A metric map's file has no unit_metres, and reads back as metres.
  map.unit_metres = 1.0;
  map.objects.pop_back();
  map.objects[0].ellipsoid = Ellipsoid({0, 0, 1}, {0.005, 0.02, 0.03}, Eigen::Matrix3d::Identity());
  io::writeMap(dir.path("metric.json"), map);
  EXPECT_FALSE(nlohmann::json::parse(io::readTextFile(dir.path("metric.json"))).contains("unit_metres"));
  EXPECT_EQ(io::readMap(dir.path("metric.json")).unit_metres, 1.0);
  map.unit_metres = -1.0;  // not a length: not written, no file left
  EXPECT_THROW(io::writeMap(dir.path("bad.json"), map), Error);
  EXPECT_FALSE(std::ifstream(dir.path("bad.json")).good());
}

TEST(MapIo, ReadsOaSlamTextMaps) {
  std::mt19937 rng(42);
  std::ostringstream text;
  text.precision(17);
  std::vector<Ellipsoid> truth;
  for (int i = 0; i < 10; ++i) {
    truth.push_back(test::randomEllipsoid(rng));
    const Eigen::Matrix4d Q = truth.back().dualQuadric() * 3.7;  // any scale
    text << i + 100 << " " << i % 3;
    for (int k = 0; k < 16; ++k) text << " " << Q(k % 4, k / 4);  // column-major
    text << "\n";
  }
  test::TempDir dir;
  io::writeFileAtomically(dir.path("map_objects_0.txt"), text.str());
  const ObjectMap map = io::readMap(dir.path("map_objects_0.txt"));
  ASSERT_EQ(map.objects.size(), 10u);
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(map.objects[i].id, i + 100);
    EXPECT_EQ(map.objects[i].category, i % 3);
    EXPECT_LT((map.objects[i].ellipsoid.center() - truth[i].center()).norm(), 1e-9);
    EXPECT_LT((map.objects[i].ellipsoid.shapeMatrix() - truth[i].shapeMatrix()).norm(), 1e-9);
  }
}

TEST(MapIo, MalformedMapsNameTheFileAndField) {
  const std::string obj =
      R"({"id": 1, "category": 41, "center": [0, 0, 1], "axes": [0.1, 0.1, 0.2], "rotation": [[1,0,0],[0,1,0],[0,0,1]]})";
  struct Case {
    std::string content, expected;
  };
  const std::string envelope_map = "{\"objects\": [" + obj + "], \"camera_envelope\": ";
  const std::vector<Case> cases = {
      {"", "empty file"},
      {envelope_map + "[]}", "camera_envelope: expected an object"},
      {envelope_map + R"({"height": [0, 1], "tilt_deg": [0, 30]}})", "camera_envelope.up: missing"},
      {envelope_map + R"({"up": [0, 0, 2], "height": [0, 1], "tilt_deg": [0, 30]}})",
       "camera_envelope.up: expected a unit vector"},
      {envelope_map + R"({"up": [0, 0, 1], "height": [1, 0], "tilt_deg": [0, 30]}})",
       "camera_envelope.height: expected [min, max]"},
      {envelope_map + R"({"up": [0, 0, 1], "height": [0, 1], "tilt_deg": [0, 190]}})",
       "camera_envelope.tilt_deg: expected [min, max] with 0 <= min"},
      {envelope_map + R"({"up": [0, 0, 1], "height": [0, "x"], "tilt_deg": [0, 30]}})", "camera_envelope.height"},
      {"{\"objects\": [" + obj.substr(0, 40), "invalid JSON"},
      {"{\"ellreloc_map\": 1}", "objects: missing"},
      {"{\"objects\": {}}", "objects: expected an array"},
      {"{\"ellreloc_map\": 2, \"objects\": []}", "unsupported version"},
      {"{\"objects\": [" + obj + "], \"unit_metres\": 0}", "unit_metres: expected a length of 1e-6 to 1e6 metres"},
      {"{\"objects\": [" + obj + "], \"unit_metres\": \"2\"}", "unit_metres"},
      {R"({"objects": [{"id": 1, "category": 41, "center": [0, 0], "axes": [1,1,1], "rotation": [[1,0,0],[0,1,0],[0,0,1]]}]})",
       "objects[0].center: expected an array of 3"},
      {R"({"objects": [{"id": 1, "category": 41, "center": [0, 0, 1], "axes": [1,-1,1], "rotation": [[1,0,0],[0,1,0],[0,0,1]]}]})",
       "objects[0].axes: semi-axes must be positive"},
      {R"({"objects": [{"id": 1, "category": 41, "center": [0, 0, 1], "axes": [1,0,1], "rotation": [[1,0,0],[0,1,0],[0,0,1]]}]})",
       "objects[0].axes"},
      {R"({"objects": [{"id": 1, "category": 41, "center": [0, 0, 1], "axes": [1,1,1], "rotation": [[2,0,0],[0,1,0],[0,0,1]]}]})",
       "objects[0].rotation: not a rotation"},
      {R"({"objects": [{"id": 1, "category": 41, "center": [0, 0, 1], "axes": [1,1,1], "rotation": [[1,0,0],[0,1,0]]}]})",
       "objects[0].rotation"},
      {R"({"objects": [{"id": "a", "category": 41}]})", "objects[0].id: expected an integer"},
      {R"({"objects": [{"id": 1, "category": 41.5}]})", "objects[0].category: expected an integer"},
      {"{\"objects\": [" + obj.substr(0, obj.size() - 1) + R"(, "category_counts": {"cup": 3}}]})",
       "objects[0].category_counts.cup: key is not an integer category"},
      {R"({"objects": [{"id": 1, "category": 41, "center": [0, "x", 1], "axes": [1,1,1], "rotation": [[1,0,0],[0,1,0],[0,0,1]]}]})",
       "objects[0].center[1]: expected a number"},
      {R"({"objects": [{"id": 1, "category": 41, "dual_quadric": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}]})",
       "objects[0].dual_quadric: the dual quadric is singular"},
      {R"({"objects": [{"id": 1, "category": 41, "dual_quadric": [1,0,0]}]})", "objects[0].dual_quadric: expected 16"},
      {"{\"objects\": [" + obj + "], \"points\": [[1, 2]]}", "points[0]: expected an array of 3"},
      {"{\"objects\": [" + obj + ", 5]}", "objects[1]: expected an object"},
      {"7 41 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0\n", "line 1: expected 16 dual-quadric entries, found 15"},
      {"7 41 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 -1 9\n", "line 1: unexpected trailing text"},
      {"# comment\n7 41 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n", "line 2: the dual quadric is singular"},
      {"seven 41\n", "line 1: expected 'track_id category_id'"},
      {"7 41 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 nan\n", "line 1"},
  };
  test::TempDir dir;
  int n = 0;
  for (const Case& c : cases) {
    const std::string path = dir.path("map" + std::to_string(n++) + ".json");
    io::writeFileAtomically(path, c.content);
    try {
      io::readMap(path);
      ADD_FAILURE() << "accepted: " << c.content;
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path, 0), 0u) << what;
      EXPECT_NE(what.find(c.expected), std::string::npos) << "expected '" << c.expected << "' in: " << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

// Well-formed objects that cannot be used are left out with a warning naming each; the rest
// of the map is read.
TEST(MapIo, UnusableObjectsAreLeftOutWithAWarningEach) {
  const auto object = [](int id, const std::string& axes) {
    return "{\"id\": " + std::to_string(id) + ", \"category\": 41, \"center\": [0, 0, 1], \"axes\": [" + axes +
           "], \"rotation\": [[1,0,0],[0,1,0],[0,0,1]]}";
  };
  test::TempDir dir;
  const std::string path = dir.path("map.json");
  io::writeFileAtomically(path, "{\"objects\": [" + object(1, "0.1, 0.2, 0.3") + ", " + object(2, "0.1, 1e-19, 0.3") +
                                    ", " + object(3, "0.1, 12, 0.3") + ", " + object(4, "0.1, 0, 0.3") + "]}");
  std::vector<std::string> warnings;
  const ObjectMap map = io::readMap(path, &warnings);
  ASSERT_EQ(map.objects.size(), 1u);
  EXPECT_EQ(map.objects[0].id, 1);
  ASSERT_EQ(warnings.size(), 3u);
  const std::vector<std::string> expected = {"object 2 left out: semi-axis 1e-19 m is below 1 mm",
                                             "object 3 left out: semi-axis 12 m is above 10 m",
                                             "object 4 left out: objects[3].axes: semi-axes must be positive"};
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(warnings[i].rfind(path + ": ", 0), 0u) << warnings[i];
    EXPECT_NE(warnings[i].find(expected[i]), std::string::npos) << warnings[i];
  }
  // OA-SLAM text: a singular dual quadric on line 2, a sphere of radius 0.5 on line 3.
  const std::string text = dir.path("map.txt");
  io::writeFileAtomically(text,
                          "7 41 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n8 41 0.25 0 0 0 0 0.25 0 0 0 0 0.25 0 0 0 0 -1\n");
  warnings.clear();
  const ObjectMap oa = io::readMap(text, &warnings);
  ASSERT_EQ(oa.objects.size(), 1u);
  EXPECT_EQ(oa.objects[0].id, 8);
  EXPECT_NEAR(oa.objects[0].ellipsoid.axes().maxCoeff(), 0.5, 1e-12);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("object 7 left out: line 1: the dual quadric is singular"), std::string::npos)
      << warnings[0];
}

TEST(MapIo, WritingAnInvalidMapLeavesNoFile) {
  test::TempDir dir;
  ObjectMap map;
  map.objects.push_back({1, 2, "", Ellipsoid({0, 0, 0}, {1, -1, 1}, Eigen::Matrix3d::Identity())});
  EXPECT_THROW(io::writeMap(dir.path("out.json"), map), Error);
  EXPECT_FALSE(std::filesystem::exists(dir.path("out.json")));
  EXPECT_THROW(io::writeMap(dir.path("no/such/dir/out.json"), ObjectMap{}), Error);
}
