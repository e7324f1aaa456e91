// One table over every reader of the library: each kind of bad input (empty, truncated,
// mistyped, NaN/inf, negative or zero sizes, huge counts, mask size mismatches, paths that do
// not exist or cannot be read as files) gives an ellreloc::Error with one line naming the file.
// And writers that fail leave no file behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <limits>

#include "ellreloc/error.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/io/rgbd.hpp"
#include "ellreloc/io/trajectory.hpp"
#include "fixtures/temp_dir.hpp"

namespace ellreloc {
namespace {

struct Reader {
  std::string name, extension;
  std::function<void(const std::string&)> read;
};

TEST(BadInput, EveryReaderRejectsEveryKindWithOneLineNamingTheFile) {
  test::TempDir dir;
  const std::vector<Reader> readers = {
      {"camera yaml", ".yaml", [](const std::string& p) { io::readCamera(p); }},
      {"camera json", ".json", [](const std::string& p) { io::readCamera(p); }},
      {"map", ".json", [](const std::string& p) { io::readMap(p); }},
      {"detections", ".json", [](const std::string& p) { io::readDetections(p); }},
      {"trajectory", ".txt", [](const std::string& p) { io::readTumTrajectory(p); }},
      {"associations", ".txt", [](const std::string& p) { io::readAssociations(p); }},
      {"depth png", ".png", [](const std::string& p) { io::readDepthPng(p); }},
  };
  // Contents that no reader accepts (each reader parses what it expects; all must refuse).
  const std::vector<std::pair<std::string, std::string>> contents = {
      {"empty", ""},
      {"blank", "  \n\t\n"},
      {"truncated json", "[{\"file_name\": \"rgb/1.png\", \"detections\": [{\"bbox\": [1, 2,"},
      {"truncated map", "{\"objects\": [{\"id\": 0, \"category_id\": 1, \"center\": [0, 0"},
      {"mistyped", "{\"objects\": \"many\", \"fx\": \"five\"}"},
      {"binary", std::string("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR", 16)},
  };
  size_t checked = 0;
  for (const Reader& r : readers) {
    for (const auto& [kind, content] : contents) {
      const std::string path = dir.path("bad_" + std::to_string(checked++) + r.extension);
      io::writeFileAtomically(path, content);
      try {
        r.read(path);
        ADD_FAILURE() << r.name << " accepted " << kind;
      } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(path), std::string::npos) << r.name << " / " << kind << ": " << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << r.name << " / " << kind << ": " << what;
      } catch (const std::exception& e) {
        ADD_FAILURE() << r.name << " / " << kind << ": not an ellreloc::Error: " << e.what();
      }
    }
    for (const std::string& missing : {dir.path("nope" + r.extension), dir.path("")}) {  // absent; a folder
      EXPECT_THROW(r.read(missing), Error) << r.name << ": " << missing;
    }
  }
}

TEST(BadInput, ValuesOutOfRangeNameTheField) {
  test::TempDir dir;
  const std::string obj = "{\"id\": 0, \"category_id\": 1, \"rotation\": [[1,0,0],[0,1,0],[0,0,1]], ";
  const std::vector<std::tuple<std::string, std::string, std::function<void(const std::string&)>>> cases = {
      {"nan_axis.json", "{\"objects\": [" + obj + "\"center\": [0,0,0], \"axes\": [0.1, NaN, 0.1]}]}",
       [](const std::string& p) { io::readMap(p); }},
      {"inf_centre.json", "{\"objects\": [" + obj + "\"center\": [1e999,0,0], \"axes\": [0.1, 0.1, 0.1]}]}",
       [](const std::string& p) { io::readMap(p); }},
      {"zero_axis.json", "{\"objects\": [" + obj + "\"center\": [0,0,0], \"axes\": [0.1, 0, 0.1]}]}",
       [](const std::string& p) { io::readMap(p); }},
      {"negative_axis.json", "{\"objects\": [" + obj + "\"center\": [0,0,0], \"axes\": [0.1, -1, 0.1]}]}",
       [](const std::string& p) { io::readMap(p); }},
      {"zero_width.json", "{\"fx\": 500, \"fy\": 500, \"cx\": 320, \"cy\": 240, \"width\": 0, \"height\": 480}",
       [](const std::string& p) { io::readCamera(p); }},
      {"negative_focal.yaml",
       "Camera.fx: -1\nCamera.fy: 500\nCamera.cx: 1\nCamera.cy: 1\nCamera.width: 2\nCamera.height: 2\n",
       [](const std::string& p) { io::readCamera(p); }},
      {"nan_box.json", "[{\"file_name\": \"a.png\", \"detections\": [{\"category_id\": 1, \"bbox\": [1, NaN, 3, 4]}]}]",
       [](const std::string& p) { io::readDetections(p); }},
      {"huge_mask.json",  // a 10^9 x 10^9 mask whose runs do not add up: refused, not allocated
       "[{\"file_name\": \"a.png\", \"detections\": [{\"category_id\": 1, \"bbox\": [1, 2, 3, 4], "
       "\"mask\": {\"size\": [1000000000, 1000000000], \"counts\": [5, 6]}}]}]",
       [](const std::string& p) { io::readDetections(p); }},
      {"mask_mismatch.json",  // 4 x 4 = 16 pixels, runs add up to 15
       "[{\"file_name\": \"a.png\", \"detections\": [{\"category_id\": 1, \"bbox\": [1, 2, 3, 4], "
       "\"mask\": {\"size\": [4, 4], \"counts\": [5, 10]}}]}]",
       [](const std::string& p) { io::readDetections(p); }},
      {"nan_pose.txt", "1.0 0 0 nan 0 0 0 1\n", [](const std::string& p) { io::readTumTrajectory(p); }},
      {"zero_quaternion.txt", "1.0 0 0 0 0 0 0 0\n", [](const std::string& p) { io::readTumTrajectory(p); }},
  };
  for (const auto& [name, content, read] : cases) {
    const std::string path = dir.path(name);
    io::writeFileAtomically(path, content);
    try {
      read(path);
      ADD_FAILURE() << name << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
}

// A JSON file that is not a map (a detections file given by mistake) is read as JSON and said
// to be the wrong JSON, not parsed as an OA-SLAM text map line by line.
TEST(BadInput, AJsonArrayGivenAsAMapIsNamedAsTheWrongJson) {
  test::TempDir dir;
  const std::string path = dir.path("detections_as_map.json");
  io::writeFileAtomically(path, "[{\"file_name\": \"a.png\", \"detections\": []}]");
  try {
    io::readMap(path);
    ADD_FAILURE() << "a detections file was read as a map";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("expected a JSON object with \"objects\""), std::string::npos) << e.what();
  }
}

TEST(BadInput, FailedWritesLeaveNoFile) {
  test::TempDir dir;
  ObjectMap bad;
  bad.objects.push_back({0, 1, "", Ellipsoid({0, 0, std::nan("")}, {1, 1, 1}, Eigen::Matrix3d::Identity())});
  EXPECT_THROW(io::writeMap(dir.path("bad.json"), bad), Error);
  EXPECT_FALSE(std::filesystem::exists(dir.path("bad.json")));
  EXPECT_THROW(io::writeFileAtomically(dir.path("no/such/folder/x.txt"), "x"), Error);
  EXPECT_FALSE(std::filesystem::exists(dir.path("no")));
  // No stray temporary file either.
  size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path(""))) files += entry.is_regular_file();
  EXPECT_EQ(files, 0u);
}

}  // namespace
}  // namespace ellreloc

namespace ellreloc {
namespace {

// Inputs must be regular files within the size limit; a PNG's declared size is checked before
// decoding; a written symlink keeps pointing at its (replaced) target.
TEST(BadInput, InputsAreRegularFilesWithinLimitsAndSymlinkOutputsStayLinks) {
  test::TempDir dir;
  EXPECT_THROW(io::readTextFile("/dev/zero"), Error);
  io::writeFileAtomically(dir.path("big.txt"), std::string(2048, 'x'));
  ::setenv("ELLRELOC_MAX_INPUT_BYTES", "1024", 1);
  try {
    io::readTextFile(dir.path("big.txt"));
    ADD_FAILURE() << "a file above the limit was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("above the input limit of 1024"), std::string::npos) << e.what();
  }
  ::unsetenv("ELLRELOC_MAX_INPUT_BYTES");
  EXPECT_EQ(io::readTextFile(dir.path("big.txt")).size(), 2048u);

  // A PNG header declaring 20000 x 20000 pixels, and nothing else.
  std::string png = std::string("\x89PNG\r\n\x1a\n", 8) + std::string("\0\0\0\x0dIHDR", 8);
  for (uint32_t v : {20000u, 20000u})
    for (int shift : {24, 16, 8, 0}) png += static_cast<char>((v >> shift) & 0xff);
  png += std::string("\x10\0\0\0\0\0\0\0\0", 9);
  io::writeFileAtomically(dir.path("huge.png"), png);
  try {
    io::readDepthPng(dir.path("huge.png"));
    ADD_FAILURE() << "a 20000 x 20000 depth PNG was decoded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("declares a 20000x20000 image"), std::string::npos) << e.what();
  }

  io::writeFileAtomically(dir.path("target.txt"), "old");
  std::filesystem::create_symlink(dir.path("target.txt"), dir.path("link.txt"));
  io::writeFileAtomically(dir.path("link.txt"), "new");
  EXPECT_TRUE(std::filesystem::is_symlink(dir.path("link.txt")));
  EXPECT_EQ(io::readTextFile(dir.path("target.txt")), "new");
  std::filesystem::create_directory(dir.path("folder"));
  EXPECT_THROW(io::writeFileAtomically(dir.path("folder"), "x"), Error);
}

}  // namespace
}  // namespace ellreloc
