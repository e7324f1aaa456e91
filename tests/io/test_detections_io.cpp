#include "ellreloc/core/projection.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/io/trajectory.hpp"

#include "fixtures/data_dir.hpp"
#include "fixtures/temp_dir.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <array>
#include <map>

using namespace ellreloc;

TEST(Rle, CompressedStringsOfHandMadeMasks) {
  // Worked by hand from pycocotools' rleToString: 5-bit groups, 0x20 = more, + 48.
  EXPECT_EQ(encodeRleString({}), "");
  EXPECT_EQ(encodeRleString({0}), "0");
  EXPECT_EQ(encodeRleString({5}), "5");    // 5 + 48
  EXPECT_EQ(encodeRleString({15}), "?");   // 15 + 48
  EXPECT_EQ(encodeRleString({16}), "`0");  // 16 has the sign bit 0x10: (16 | 0x20) + 48, then 0
  // 40 = 8 + 1 * 32 -> (8 | 0x20) + 48 = 'X', then '1'; the fourth run is coded as
  // 40 - 2 = 38 (minus the run two before) -> 'V', '1'.
  EXPECT_EQ(encodeRleString({3, 2, 40, 40}), "32X1V1");
  EXPECT_EQ(encodeRleString({3, 2, 1, 0}), "321N");  // 0 - 2 = -2 -> 30 + 48 = 'N'
  EXPECT_EQ(decodeRleString("32X1V1"), std::optional<std::vector<uint32_t>>({3, 2, 40, 40}));
  EXPECT_EQ(decodeRleString("321N"), std::optional<std::vector<uint32_t>>({3, 2, 1, 0}));
}

TEST(Rle, DecodeInvertsEncode) {
  std::mt19937 rng(61);
  for (int i = 0; i < 2000; ++i) {
    std::vector<uint32_t> counts(1 + rng() % 40);
    for (auto& c : counts) c = (rng() % 4 == 0) ? rng() % 1000000 : rng() % 50;
    const auto back = decodeRleString(encodeRleString(counts));
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(*back, counts);
  }
  EXPECT_FALSE(decodeRleString("P").has_value());        // truncated group
  EXPECT_FALSE(decodeRleString(std::string(1, '/')).has_value());  // below the alphabet
  EXPECT_FALSE(decodeRleString("\x7f").has_value());     // above it
}

TEST(Rle, BitExactWithPycocotoolsOnTheLabelmeMasks) {
  const auto strings = io::readDetections(test::dataPath("labelme_masks/detections.json"));
  const auto lists = io::readDetections(test::dataPath("labelme_masks/detections.rle_list.json"));
  const auto raw = nlohmann::json::parse(io::readTextFile(test::dataPath("labelme_masks/detections.json")));
  ASSERT_EQ(strings.size(), lists.size());
  int masks = 0;
  for (size_t f = 0; f < strings.size(); ++f) {
    ASSERT_EQ(strings[f].detections.size(), lists[f].detections.size());
    for (size_t d = 0; d < strings[f].detections.size(); ++d) {
      const auto& a = strings[f].detections[d].mask;
      const auto& b = lists[f].detections[d].mask;
      ASSERT_TRUE(a && b);
      EXPECT_EQ(a->counts, b->counts);
      EXPECT_EQ(encodeRleString(b->counts), raw[f]["detections"][d]["mask"]["counts"].get<std::string>());
      ++masks;
    }
  }
  EXPECT_EQ(masks, 12);
}

TEST(Rle, LabelmeMasksMatchTheInstancePngs) {
  // Decode each RLE and compare with the instance PNG: nearly every mask pixel shows one
  // instance. OpenCV expands the palette PNG to colours, so instances are told by colour.
  const auto frames = io::readDetections(test::dataPath("labelme_masks/detections.json"));
  for (const auto& frame : frames) {
    const std::string stem = frame.timestampText();
    const cv::Mat png = cv::imread(test::dataPath("labelme_masks/data_dataset_voc/SegmentationObject/" + stem + ".png"),
                                   cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(png.empty()) << stem;
    ASSERT_EQ(png.type(), CV_8UC3);
    for (const auto& det : frame.detections) {
      const RleMask& m = *det.mask;
      ASSERT_EQ(m.height, png.rows);
      ASSERT_EQ(m.width, png.cols);
      std::map<std::array<uint8_t, 3>, long> labels;
      long pixels = 0, pos = 0;
      for (size_t i = 0; i < m.counts.size(); ++i) {
        for (uint32_t k = 0; k < m.counts[i]; ++k, ++pos) {
          if (i % 2 == 0) continue;
          const int x = static_cast<int>(pos / m.height), y = static_cast<int>(pos % m.height);
          const cv::Vec3b c = png.at<cv::Vec3b>(y, x);
          ++labels[{c[0], c[1], c[2]}];
          ++pixels;
        }
      }
      ASSERT_GT(pixels, 0);
      const auto best = std::max_element(labels.begin(), labels.end(),
                                         [](const auto& a, const auto& b) { return a.second < b.second; });
      EXPECT_NE(best->first, (std::array<uint8_t, 3>{0, 0, 0}));  // not background
      EXPECT_GT(static_cast<double>(best->second) / pixels, 0.95);
    }
  }
}

TEST(DetectionsIo, ReadsTheFr2KeyframeBoxes) {
  const auto frames = io::readDetections(test::dataPath("tum_fr2_desk/keyframes.detections.json"));
  ASSERT_EQ(frames.size(), 198u);
  size_t boxes = 0, associated = 0;
  for (const auto& f : frames) {
    boxes += f.detections.size();
    for (const auto& d : f.detections) associated += d.object_id.has_value();
    ASSERT_TRUE(f.timestamp().has_value());
  }
  EXPECT_EQ(boxes, 1200u);
  EXPECT_EQ(associated, 1185u);
  EXPECT_EQ(frames[0].timestampText(), "1311868164.363181");
  EXPECT_DOUBLE_EQ(*frames[0].timestamp(), 1311868164.363181);
}

TEST(DetectionsIo, PolygonFileReadsAndRoundTripPreservesEverything) {
  auto frames = io::readDetections(test::dataPath("labelme_masks/detections.polygon.json"));
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_GE(frames[0].detections[0].polygon.size(), 3u);
  const auto masks = io::readDetections(test::dataPath("labelme_masks/detections.json"));
  frames[0].detections[0].mask = masks[0].detections[0].mask;
  frames[0].detections[0].ellipse = Ellipse({100, 50}, {30, 20}, 0.25);
  frames[0].detections[0].regular = true;
  frames[0].detections[0].object_id = 12;
  frames[1].keypoints = {{3, {10.5, 20.25}}, {0, {1, 2}}};
  test::TempDir dir;
  io::writeDetections(dir.path("d.json"), frames);
  const auto back = io::readDetections(dir.path("d.json"));
  ASSERT_EQ(back.size(), frames.size());
  const Detection& d = back[0].detections[0];
  EXPECT_EQ(d.polygon, frames[0].detections[0].polygon);
  EXPECT_EQ(d.mask->counts, masks[0].detections[0].mask->counts);
  EXPECT_EQ(d.ellipse->center(), Eigen::Vector2d(100, 50));
  EXPECT_EQ(d.ellipse->angle(), 0.25);
  EXPECT_EQ(d.regular, std::optional<bool>(true));
  EXPECT_EQ(d.object_id, std::optional<int>(12));
  ASSERT_EQ(back[1].keypoints.size(), 2u);
  EXPECT_EQ(back[1].keypoints[0].point_index, 3);
  EXPECT_EQ(back[1].keypoints[0].uv, Eigen::Vector2d(10.5, 20.25));
  EXPECT_EQ(back[2].detections[1].bbox.x2, frames[2].detections[1].bbox.x2);
}

TEST(DetectionsIo, MalformedFilesNameTheField) {
  const std::string box = R"("category_id": 41, "bbox": [1, 2, 30, 40])";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "empty file"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{" + box, "invalid JSON"},
      {"{}", "expected an array of frames"},
      {"[{\"detections\": []}]", "[0].file_name: missing"},
      {"[{\"file_name\": \"\", \"detections\": []}]", "[0].file_name: expected a non-empty string"},
      {"[{\"file_name\": \"a.png\", \"detections\": {}}]", "[0].detections: expected an array"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{\"category_id\": 41}]}]", "[0].detections[0].bbox: missing"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{\"category_id\": 41, \"bbox\": [1, 2, 3]}]}]",
       "bbox: expected an array of 4"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{\"category_id\": 41, \"bbox\": [10, 2, 3, 40]}]}]",
       "bbox: expected [x1, y1, x2, y2] with x1 < x2"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{\"category_id\": \"cup\", \"bbox\": [1, 2, 3, 4]}]}]",
       "category_id: expected an integer"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{\"category_id\": 7.5, \"bbox\": [1, 2, 3, 4]}]}]",
       "category_id: expected an integer, got 7.5"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{" + box + ", \"mask\": {\"size\": [4, 4], \"counts\": 16}}]}]",
       "mask.counts: expected a compressed RLE string or a list of run lengths"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{" + box + ", \"detection_score\": -1}]}]",
       "detection_score: must be >= 0"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{" + box +
           ", \"mask\": {\"size\": [4, 4], \"counts\": [3, 20]}}]}]",
       "mask.counts: runs sum to 23, expected height x width = 16"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{" + box +
           ", \"mask\": {\"size\": [4, 4], \"counts\": [3, -2, 15]}}]}]",
       "mask.counts[1]: run lengths must be >= 0"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{" + box + ", \"mask\": {\"size\": [4, 4], \"counts\": \"P\"}}]}]",
       "mask.counts: malformed compressed RLE string"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{" + box + ", \"mask\": {\"size\": [0, 4], \"counts\": []}}]}]",
       "mask.size: height and width must be positive"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{" + box + ", \"mask\": {\"counts\": []}}]}]",
       "mask.size: missing"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{" + box + ", \"polygon\": [[1, 2], [3, 4]]}]}]",
       "polygon: expected at least 3"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{" + box +
           R"(, "ellipse": {"center": [1, 2], "axes": [0, 2], "angle": 0}}]}])",
       "ellipse.axes: semi-axes must be positive"},
      {"[{\"file_name\": \"a.png\", \"detections\": [{" + box +
           R"(, "ellipse": {"center": [1, 2], "axes": [1, 2]}}]}])",
       "ellipse.angle: missing"},
      {"[{\"file_name\": \"a.png\", \"detections\": [], \"keypoints\": [[1, 2]]}]",
       "[0].keypoints[0]: expected [point_index, u, v]"},
      {"[{\"file_name\": \"a.png\", \"detections\": [], \"keypoints\": [[-1, 2, 3]]}]",
       "[0].keypoints[0][0]: point index must be >= 0"},
      {"[{\"file_name\": \"a.png\", \"detections\": []}, {\"file_name\": \"a.png\", \"detections\": []}]",
       "[1].file_name: 'a.png' repeats frame [0]"},
  };
  test::TempDir dir;
  int n = 0;
  for (const auto& [content, expected] : cases) {
    const std::string path = dir.path("d" + std::to_string(n++) + ".json");
    io::writeFileAtomically(path, content);
    try {
      io::readDetections(path);
      ADD_FAILURE() << "accepted: " << content;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << "expected '" << expected << "' in: " << e.what();
      EXPECT_EQ(std::string(e.what()).rfind(path, 0), 0u) << e.what();
    }
  }
}

// Some writers emit integers as floats: 7.0 is read as 7 (7.5 is refused, above).
TEST(DetectionsIo, IntegersWrittenAsWholeFloatsAreRead) {
  test::TempDir dir;
  const std::string path = dir.path("floats.json");
  io::writeFileAtomically(path,
                          R"([{"file_name": "a.png", "detections": [{"category_id": 7.0, "bbox": [1, 2, 3, 4]}]}])");
  const std::vector<DetectionFrame> frames = io::readDetections(path);
  ASSERT_EQ(frames.size(), 1u);
  ASSERT_EQ(frames[0].detections.size(), 1u);
  EXPECT_EQ(frames[0].detections[0].category_id, 7);
}

// The data's README: median IoU between each associated box and the (image-clipped) bounding
// box of its ellipsoid projected with the keyframe pose is 0.598; with the pose direction
// inverted it drops to 0. This pins down the pose convention and the projection on real data.
TEST(RealData, Fr2ProjectedEllipsoidsMatchTheAssociatedBoxes) {
  const Intrinsics K = io::readCamera(test::dataPath("tum_fr2_desk/camera.yaml"));
  const ObjectMap map = io::readMap(test::dataPath("tum_fr2_desk/map.json"));
  const auto poses = io::readTumTrajectory(test::dataPath("tum_fr2_desk/keyframes.groundtruth.txt"));
  const auto frames = io::readDetections(test::dataPath("tum_fr2_desk/keyframes.detections.json"));
  std::map<int, const Ellipsoid*> by_id;
  for (const auto& o : map.objects) by_id[o.id] = &o.ellipsoid;
  std::vector<double> ious;
  for (const auto& frame : frames) {
    const auto k = io::findNearest(poses, *frame.timestamp());
    ASSERT_TRUE(k.has_value());
    for (const auto& det : frame.detections) {
      if (!det.object_id) continue;
      const Projection p = project(*by_id.at(*det.object_id), K, poses[*k].pose);
      if (!p.ok()) {
        ious.push_back(0.0);
        continue;
      }
      const Box image(-0.5, -0.5, K.width - 0.5, K.height - 0.5);
      ious.push_back(boxIoU(p.ellipse.boundingBox().intersection(image), det.bbox));
    }
  }
  ASSERT_EQ(ious.size(), 1185u);
  std::nth_element(ious.begin(), ious.begin() + ious.size() / 2, ious.end());
  EXPECT_NEAR(ious[ious.size() / 2], 0.598, 0.005);
}
