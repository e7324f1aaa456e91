#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "ellreloc/error.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/rgbd.hpp"
#include "fixtures/data_dir.hpp"
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

TEST(RgbdIo, AssociationIndexFindsTheNamedImageElseTheNearestTime) {
  test::TempDir dir;
  // Colour images 33 ms apart; the third is named twice (the last line counts).
  io::writeFileAtomically(dir.path("associate.txt"),
                          "10.000 rgb/a.png 10.001 depth/a.png\n"
                          "10.033 rgb/b.png 10.034 depth/b.png\n"
                          "10.066 rgb/c.png 10.067 depth/c1.png\n"
                          "10.300 rgb/c.png 10.301 depth/c2.png\n");
  const std::vector<io::Association> lines = io::readAssociations(dir.path("associate.txt"));
  const io::AssociationIndex index(lines);
  const auto depthOf = [&](const std::string& rgb, std::optional<double> t) -> std::string {
    const io::Association* a = index.find(rgb, t);
    return a ? std::filesystem::path(a->depth_path).filename().string() : "none";
  };
  // By name, however the path is spelt, whatever the time says.
  EXPECT_EQ(depthOf(dir.path("rgb/b.png"), 10.0), "b.png");
  EXPECT_EQ(depthOf(dir.path("rgb/../rgb/./b.png"), std::nullopt), "b.png");
  EXPECT_EQ(depthOf(dir.path("rgb/c.png"), std::nullopt), "c2.png");
  // Else by time: the nearest line within 0.02 s, on either side of it.
  EXPECT_EQ(depthOf(dir.path("rgb/x.png"), 10.020), "b.png");  // 13 ms to b, 20 ms to a
  EXPECT_EQ(depthOf(dir.path("rgb/x.png"), 10.013), "a.png");  // 13 ms to a, 20 ms to b
  EXPECT_EQ(depthOf(dir.path("rgb/x.png"), 10.3199), "c2.png");
  EXPECT_EQ(depthOf(dir.path("rgb/x.png"), 9.9), "none");   // before every line
  EXPECT_EQ(depthOf(dir.path("rgb/x.png"), 10.2), "none");  // between lines, 0.13 s from both
  EXPECT_EQ(depthOf(dir.path("rgb/x.png"), 11.0), "none");  // after every line
  EXPECT_EQ(depthOf(dir.path("rgb/x.png"), std::nullopt), "none");
  EXPECT_EQ(depthOf(dir.path("rgb/x.png"), std::nan("")), "none");
  EXPECT_EQ(depthOf("", std::nullopt), "none");  // no image named, no exception
  EXPECT_EQ(depthOf("", 10.0), "a.png");
  // The same as reading every line for the nearest, at times over the whole sequence.
  for (double t = 9.95; t < 10.36; t += 0.0007) {
    std::string expected = "none";
    double best = 0.02;
    for (const io::Association& a : lines)
      if (std::abs(a.rgb_time - t) <= best)
        best = std::abs(a.rgb_time - t), expected = std::filesystem::path(a.depth_path).filename().string();
    EXPECT_EQ(depthOf(dir.path("rgb/x.png"), t), expected) << t;
  }
  EXPECT_EQ(io::AssociationIndex({}).find(dir.path("rgb/a.png"), 10.0), nullptr);
  EXPECT_THROW(io::AssociationIndex(lines, -0.01), Error);
  EXPECT_THROW(io::AssociationIndex(lines, std::nan("")), Error);
  EXPECT_THROW(io::AssociationIndex(lines, INFINITY), Error);
}
