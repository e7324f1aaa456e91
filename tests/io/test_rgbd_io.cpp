#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "fixtures/data_dir.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/rgbd.hpp"
#include "fixtures/temp_dir.hpp"

using namespace ellreloc;

TEST(RgbdIo, ReadsTheFr3CabinetAssociationsAndDepth) {
  const auto assoc = io::readAssociations(test::dataPath("tum_fr3_cabinet/associate.txt"));
  ASSERT_FALSE(assoc.empty());
  EXPECT_DOUBLE_EQ(assoc[0].rgb_time, 1341841278.8427);
  for (const auto& a : assoc) {
    EXPECT_TRUE(std::filesystem::exists(a.rgb_path)) << a.rgb_path;
    EXPECT_TRUE(std::filesystem::exists(a.depth_path)) << a.depth_path;
  }
  const DepthImage d = io::readDepthPng(assoc[0].depth_path);
  EXPECT_EQ(d.width, 640);
  EXPECT_EQ(d.height, 480);
  // Independent check: the raw 16-bit values through OpenCV, divided by 5000.
  const cv::Mat raw = cv::imread(assoc[0].depth_path, cv::IMREAD_UNCHANGED);
  int valid = 0;
  for (int y = 0; y < 480; y += 7)
    for (int x = 0; x < 640; x += 7) {
      EXPECT_FLOAT_EQ(d.at(x, y), static_cast<float>(raw.at<uint16_t>(y, x) / 5000.0));
      valid += d.at(x, y) > 0;
    }
  EXPECT_GT(valid, 1000);
}

TEST(RgbdIo, DepthRoundTripAndErrors) {
  test::TempDir dir;
  DepthImage d;
  d.width = 4;
  d.height = 3;
  d.metres = {0.0f, 0.5f, 1.0002f, 2.5f, 13.107f, 20.0f, -1.0f, 0.0002f, 3.3f, 1.0f, 1.0f, 1.0f};
  io::writeDepthPng(dir.path("d.png"), d);
  const DepthImage back = io::readDepthPng(dir.path("d.png"));
  ASSERT_EQ(back.metres.size(), d.metres.size());
  EXPECT_FLOAT_EQ(back.at(1, 0), 0.5f);
  EXPECT_FLOAT_EQ(back.at(2, 0), 1.0002f);
  EXPECT_FLOAT_EQ(back.at(0, 1), 13.107f);  // 65535 units
  EXPECT_FLOAT_EQ(back.at(1, 1), 0.0f);     // beyond 16 bits: no reading
  EXPECT_FLOAT_EQ(back.at(2, 1), 0.0f);     // negative: no reading
  EXPECT_FLOAT_EQ(back.at(3, 1), 0.0002f);
  // Errors name the file.
  EXPECT_THROW(io::readDepthPng(dir.path("missing.png")), Error);
  io::writeFileAtomically(dir.path("junk.png"), "not a png");
  EXPECT_THROW(io::readDepthPng(dir.path("junk.png")), Error);
  cv::imwrite(dir.path("rgb.png"), cv::Mat(4, 4, CV_8UC3, cv::Scalar(1, 2, 3)));
  try {
    io::readDepthPng(dir.path("rgb.png"));
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("16-bit"), std::string::npos);
  }
  DepthImage bad = d;
  bad.metres.pop_back();
  EXPECT_THROW(io::writeDepthPng(dir.path("bad.png"), bad), Error);
  EXPECT_FALSE(std::filesystem::exists(dir.path("bad.png")));
  io::writeFileAtomically(dir.path("a.txt"), "1.0 rgb/1.png 1.0\n");
  EXPECT_THROW(io::readAssociations(dir.path("a.txt")), Error);
  io::writeFileAtomically(dir.path("b.txt"), "# nothing\n");
  EXPECT_THROW(io::readAssociations(dir.path("b.txt")), Error);
}
