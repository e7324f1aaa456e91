#include <gtest/gtest.h>

#include <functional>

#include "ellreloc/error.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/files.hpp"
#include "fixtures/data_dir.hpp"
#include "fixtures/temp_dir.hpp"

using namespace ellreloc;

TEST(CameraIo, ReadsTheOrbSlamYamlOfFr2) {
  const Intrinsics K = io::readCamera(test::dataPath("tum_fr2_desk/camera.yaml"));
  EXPECT_DOUBLE_EQ(K.fx, 520.90862);
  EXPECT_DOUBLE_EQ(K.fy, 521.007327);
  EXPECT_DOUBLE_EQ(K.cx, 325.141442);
  EXPECT_DOUBLE_EQ(K.cy, 249.701764);
  EXPECT_EQ(K.width, 640);
  EXPECT_EQ(K.height, 480);
}

TEST(CameraIo, JsonAndYamlRoundTrips) {
  test::TempDir dir;
  const Intrinsics K(517.3, 516.5, 318.6, 255.3, 640, 480);
  for (const std::string name : {"cam.json", "cam.yaml"}) {
    io::writeCamera(dir.path(name), K);
    const Intrinsics back = io::readCamera(dir.path(name));
    EXPECT_DOUBLE_EQ(back.fx, K.fx);
    EXPECT_DOUBLE_EQ(back.fy, K.fy);
    EXPECT_DOUBLE_EQ(back.cx, K.cx);
    EXPECT_DOUBLE_EQ(back.cy, K.cy);
    EXPECT_EQ(back.width, K.width);
    EXPECT_EQ(back.height, K.height);
  }
}

namespace {

struct Case {
  std::string name, content, expected;
};

/// Each case written to a file that `read` must turn down with one line naming the file and
/// holding `expected`.
void expectErrors(const test::TempDir& dir, const std::vector<Case>& cases,
                  const std::function<void(const std::string&)>& read) {
  for (const Case& c : cases) {
    io::writeFileAtomically(dir.path(c.name), c.content);
    try {
      read(dir.path(c.name));
      ADD_FAILURE() << c.name << " was accepted";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(c.name), std::string::npos) << what;
      EXPECT_NE(what.find(c.expected), std::string::npos) << c.name << ": " << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
    }
  }
}

}  // namespace

TEST(CameraIo, MalformedFilesNameTheFileAndKey) {
  test::TempDir dir;
  const std::vector<Case> cases = {
      {"empty.json", "", "empty file"},
      {"trunc.json", "{\"fx\": 500, \"fy\":", "invalid JSON"},
      {"missing.json", "{\"fx\": 500, \"fy\": 500, \"cx\": 320, \"cy\": 240, \"width\": 640}", "height: missing"},
      {"type.json", "{\"fx\": \"500\", \"fy\": 500, \"cx\": 320, \"cy\": 240, \"width\": 640, \"height\": 480}",
       "fx: expected a number"},
      {"neg.json", "{\"fx\": -500, \"fy\": 500, \"cx\": 320, \"cy\": 240, \"width\": 640, \"height\": 480}",
       "positive"},
      {"zero.json", "{\"fx\": 500, \"fy\": 500, \"cx\": 320, \"cy\": 240, \"width\": 0, \"height\": 480}", "positive"},
      {"frac.json", "{\"fx\": 500, \"fy\": 500, \"cx\": 320, \"cy\": 240, \"width\": 640.5, \"height\": 480}",
       "width: expected an integer"},
      {"array.json", "[1, 2, 3]", "expected an object"},
      {"empty.yaml", "  \n", "empty file"},
      {"missing.yaml",
       "%YAML:1.0\nCamera.fx: 500\nCamera.fy: 500\nCamera.cx: 320\nCamera.width: 640\nCamera.height: 480\n",
       "Camera.cy: missing"},
      {"text.yaml",
       "%YAML:1.0\nCamera.fx: abc\nCamera.fy: 500\nCamera.cx: 320\nCamera.cy: 2\nCamera.width: 640\nCamera.height: "
       "480\n",
       "Camera.fx"},
      {"twice.yaml", "Camera.fx: 500\nCamera.fx: 501\n", "line 2: Camera.fx given twice"},
      {"nocolon.yaml", "Camera.fx 500\n", "line 1: expected key: value"},
      {"trailing.yaml",
       "Camera.fx: 500px\nCamera.fy: 500\nCamera.cx: 320\nCamera.cy: 2\nCamera.width: 640\nCamera.height: 480\n",
       "Camera.fx: expected a number"},
      // Found by fuzzing: deep nesting made OpenCV's YAML parser abort the process.
      {"nested.yaml", "{\"fx\": 525.0, :y\"f \"525.1[[[[[[[[[[[[[[[[[[[[[[[[[[[[0, \"cxfx\":. 319",
       "Camera.fx: missing"},
  };
  expectErrors(dir, cases, [](const std::string& path) { io::readCamera(path); });
  EXPECT_THROW(io::readCamera(dir.path("does-not-exist.yaml")), Error);
  // Nested maps and matrices of other keys (indented) are skipped; comments after values too.
  io::writeFileAtomically(dir.path("nested_ok.yaml"),
                          "%YAML:1.0\n---\nCamera.fx: 500 # focal\nCamera.fy: 501\nCamera.cx: 320\nCamera.cy: 240\n"
                          "Camera.width: 640\nCamera.height: 480\nTbc: !!opencv-matrix\n  rows: 4\n  data: [1, 0]\n");
  const Intrinsics K = io::readCamera(dir.path("nested_ok.yaml"));
  EXPECT_EQ(K.fx, 500.0);
  EXPECT_EQ(K.fy, 501.0);
  EXPECT_EQ(K.height, 480);
  EXPECT_THROW(io::readCamera(dir.path("")), Error);  // a directory
}

TEST(CameraIo, ReadsTheLensOfFr2AndNoneWhereTheKeysAreLeftOut) {
  const Lens lens = io::readLens(test::dataPath("tum_fr2_desk/camera.yaml"));
  EXPECT_DOUBLE_EQ(lens.intrinsics.fx, 520.90862);
  EXPECT_DOUBLE_EQ(lens.distortion.k1, 0.231222);
  EXPECT_DOUBLE_EQ(lens.distortion.k2, -0.784899);
  EXPECT_DOUBLE_EQ(lens.distortion.p1, -0.003257);
  EXPECT_DOUBLE_EQ(lens.distortion.p2, -0.000105);
  EXPECT_DOUBLE_EQ(lens.distortion.k3, 0.917205);
  test::TempDir dir;
  io::writeCamera(dir.path("plain.yaml"), lens.intrinsics);
  io::writeCamera(dir.path("plain.json"), lens.intrinsics);
  EXPECT_TRUE(io::readDistortion(dir.path("plain.yaml")).isZero());
  EXPECT_TRUE(io::readDistortion(dir.path("plain.json")).isZero());
  io::writeFileAtomically(dir.path("lens.json"),
                          "{\"fx\": 500, \"fy\": 500, \"cx\": 320, \"cy\": 240, \"width\": 640, \"height\": 480, "
                          "\"k1\": -0.1, \"p2\": 0.001}");
  const Distortion d = io::readDistortion(dir.path("lens.json"));
  EXPECT_EQ(d.k1, -0.1);
  EXPECT_EQ(d.p2, 0.001);
  EXPECT_EQ(d.k2, 0.0);
}

TEST(CameraIo, ABadLensNamesTheFileAndTheKey) {
  test::TempDir dir;
  const std::string intrinsics =
      "Camera.fx: 500\nCamera.fy: 500\nCamera.cx: 320\nCamera.cy: 240\nCamera.width: 640\nCamera.height: 480\n";
  const std::vector<Case> cases = {
      {"text.yaml", intrinsics + "Camera.k1: strong\n", "Camera.k1: expected a number"},
      {"nan.yaml", intrinsics + "Camera.k2: nan\n", "Camera.k2: not a finite number"},
      {"folds.yaml", intrinsics + "Camera.k1: -0.9\n", "folds over"},
      {"type.json",
       "{\"fx\": 500, \"fy\": 500, \"cx\": 320, \"cy\": 240, \"width\": 640, \"height\": 480, \"k3\": \"0.1\"}",
       "k3: expected a number"},
  };
  expectErrors(dir, cases, [](const std::string& path) { io::readLens(path); });
}
