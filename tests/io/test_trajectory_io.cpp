#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "ellreloc/error.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/trajectory.hpp"
#include "fixtures/data_dir.hpp"
#include "fixtures/random_geometry.hpp"
#include "fixtures/temp_dir.hpp"

using namespace ellreloc;

TEST(TrajectoryIo, ReadsTumFilesAsWorldToCamera) {
  test::TempDir dir;
  // Camera at (1, 2, 3), rotated 90 degrees about z: q = (0, 0, sin 45, cos 45).
  io::writeFileAtomically(dir.path("t.txt"), "# header\n\n1.5 1 2 3 0 0 0.7071067811865476 0.7071067811865476\n");
  const auto poses = io::readTumTrajectory(dir.path("t.txt"));
  ASSERT_EQ(poses.size(), 1u);
  EXPECT_DOUBLE_EQ(poses[0].timestamp, 1.5);
  EXPECT_LT((poses[0].pose.center() - Eigen::Vector3d(1, 2, 3)).norm(), 1e-12);
  // The camera's x axis points along world y: a world point one metre along +y from the
  // camera is at camera x = +1.
  EXPECT_LT((poses[0].pose.transform(Eigen::Vector3d(1, 3, 3)) - Eigen::Vector3d(1, 0, 0)).norm(), 1e-12);
}

TEST(TrajectoryIo, RoundTripAndNearestTimestamp) {
  std::mt19937 rng(51);
  std::vector<io::StampedPose> poses;
  for (int i = 0; i < 50; ++i) poses.push_back({1311868164.0 + 0.1 * i, test::randomLookAtPose(rng)});
  test::TempDir dir;
  io::writeTumTrajectory(dir.path("t.txt"), poses);
  const auto back = io::readTumTrajectory(dir.path("t.txt"));
  ASSERT_EQ(back.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_NEAR(back[i].timestamp, poses[i].timestamp, 1e-6);
    EXPECT_LT((back[i].pose.rotation() - poses[i].pose.rotation()).norm(), 1e-12);
    EXPECT_LT((back[i].pose.translation() - poses[i].pose.translation()).norm(), 1e-12);
  }
  EXPECT_EQ(io::findNearest(back, 1311868164.0 + 0.1 * 7 + 0.015), std::optional<size_t>(7));
  EXPECT_EQ(io::findNearest(back, 1311868164.0 + 0.1 * 7 - 0.019), std::optional<size_t>(7));
  EXPECT_EQ(io::findNearest(back, 1311868164.0 + 0.1 * 7 + 0.03), std::nullopt);
  EXPECT_EQ(io::findNearest(back, 0.0), std::nullopt);
}

TEST(TrajectoryIo, AFramesPoseIsTheOneNearestToItsFileNamesTimestamp) {
  std::vector<io::StampedPose> poses(3);
  for (int i = 0; i < 3; ++i) {
    poses[i].timestamp = 100.0 + i;
    poses[i].pose = Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(i, 0, 0));
  }
  const auto frame = [](const std::string& name) { return DetectionFrame{name, {}, {}}; };
  const Pose* p = io::framePose(poses, frame("rgb/101.01.png"));
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p, &poses[1].pose);
  EXPECT_EQ(io::framePose(poses, frame("depth/99.99.png")), &poses[0].pose);
  EXPECT_EQ(io::framePose(poses, frame("rgb/101.5.png")), nullptr);       // beyond the 0.02 s tolerance
  EXPECT_EQ(io::framePose(poses, frame("rgb/101.4.png"), 0.6), &poses[1].pose);
  EXPECT_EQ(io::framePose(poses, frame("rgb/frame_0001.png")), nullptr);  // no timestamp in the name
  EXPECT_EQ(io::framePose({}, frame("rgb/101.png")), nullptr);
}

TEST(TrajectoryIo, TheTimeIndexFindsWhatAPassOverEveryPoseFinds) {
  // Unsorted times on a grid of binary fractions (exact in floating point), so that many lookups
  // are ties: equally near on both sides, or several poses at one time; one time that is not
  // finite is never found.
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> tick(0, 40);
  std::vector<io::StampedPose> poses(60);
  for (io::StampedPose& p : poses) p.timestamp = 5.0 + 0.25 * tick(rng);
  poses[13].timestamp = std::nan("");
  const io::TimeIndex by_time = io::timeIndex(poses);
  int found = 0, ties = 0;
  for (double t = 4.0; t < 16.0; t += 0.0625) {
    for (const double tolerance : {0.0, 0.125, 0.25, 3.0}) {
      const std::optional<size_t> k = io::findNearest(poses, t, tolerance);
      EXPECT_EQ(by_time.nearest(t, tolerance), k) << t << " within " << tolerance;
      found += k.has_value();
      if (k) ties += std::count_if(poses.begin(), poses.end(), [&](const io::StampedPose& p) {
                       return std::abs(p.timestamp - t) == std::abs(poses[*k].timestamp - t);
                     }) > 1;
    }
  }
  EXPECT_GT(found, 300);  // the lookups above do find poses, and many among equals
  EXPECT_GT(ties, 100);
  EXPECT_EQ(by_time.nearest(std::nan(""), 1.0), std::nullopt);
  EXPECT_EQ(by_time.nearest(5.1, std::nan("")), std::nullopt);
  EXPECT_EQ(by_time.nearest(5.1, -1.0), std::nullopt);
  EXPECT_EQ(io::TimeIndex({}).nearest(5.1, 1.0), std::nullopt);
  // A frame's pose through the index is the one framePose finds by reading every pose.
  const auto frame = [](const std::string& name) { return DetectionFrame{name, {}, {}}; };
  for (const char* name : {"rgb/5.25.png", "rgb/5.26.png", "rgb/4.9.png", "rgb/none.png"})
    EXPECT_EQ(io::framePose(poses, by_time, frame(name)), io::framePose(poses, frame(name))) << name;
}

TEST(TrajectoryIo, ReadsTheFr2Keyframes) {
  const auto poses = io::readTumTrajectory(test::dataPath("tum_fr2_desk/keyframes.groundtruth.txt"));
  EXPECT_EQ(poses.size(), 198u);
  for (const auto& p : poses) EXPECT_TRUE(p.pose.isValid());
}

TEST(TrajectoryIo, MalformedLinesAreNamed) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "no poses"},
      {"# only a comment\n", "no poses"},
      {"1.0 1 2 3 0 0 0\n", "line 1: expected"},
      {"1.0 1 2 3 0 0 0 1 extra\n", "line 1: unexpected trailing text"},
      {"1.0 1 2 3 0 0 0 1\n2.0 1 2 3 0 0 0 0\n", "line 2: zero quaternion"},
      {"1.0 1 2 x 0 0 0 1\n", "line 1: expected"},
      {"1.0 1 2 1e999 0 0 0 1\n", "line 1"},
      {"1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 1\n1.00 0 0 0 0 0 0 1\n", "line 3: timestamp 1.00 repeats line 1"},
      {"nan 0 0 0 0 0 0 1\n", "line 1: timestamp 'nan' is not a finite number"},
      {"0x10 0 0 0 0 0 0 1\n", "line 1: timestamp '0x10' is not a finite number"},
  };
  test::TempDir dir;
  int n = 0;
  for (const auto& [content, expected] : cases) {
    const std::string path = dir.path("t" + std::to_string(n++) + ".txt");
    io::writeFileAtomically(path, content);
    try {
      io::readTumTrajectory(path);
      ADD_FAILURE() << "accepted: " << content;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind(path, 0), 0u) << e.what();
    }
  }
}

TEST(TrajectoryIo, TimestampsAreWrittenExactlyAsRead) {
  // Two stamps 0.3 us apart, below the 6 decimals of the usual printf, keep their own text;
  // stamps given only as numbers get the shortest text that reads back as the same double.
  test::TempDir dir;
  const std::string in = "1311868164.3631811 0 0 0 0 0 0 1\n1311868164.3631814 1 0 0 0 0 0 1\n1e3 2 0 0 0 0 0 1\n";
  io::writeFileAtomically(dir.path("in.txt"), in);
  std::vector<io::StampedPose> poses = io::readTumTrajectory(dir.path("in.txt"));
  ASSERT_EQ(poses.size(), 3u);
  EXPECT_EQ(poses[0].stamp, "1311868164.3631811");
  EXPECT_NE(poses[0].timestamp, poses[1].timestamp);
  poses.push_back({1311868164.1, poses[0].pose});
  poses.push_back({0.1 + 0.2, poses[0].pose});
  io::writeTumTrajectory(dir.path("out.txt"), poses);
  std::vector<std::string> stamps;
  for (const io::StampedPose& p : io::readTumTrajectory(dir.path("out.txt"))) stamps.push_back(p.stamp);
  EXPECT_EQ(stamps, (std::vector<std::string>{"1311868164.3631811", "1311868164.3631814", "1e3", "1311868164.1",
                                              "0.30000000000000004"}));
  // The writer refuses what the reader would refuse, and leaves no file.
  const std::vector<std::vector<io::StampedPose>> refused = {
      {poses[0], {1311868164.3631811, poses[0].pose}},  // the same timestamp twice
      {{1.0, poses[0].pose, "1.0 2"}},                  // a stamp that is not one number
  };
  for (const auto& bad : refused) {
    EXPECT_THROW(io::writeTumTrajectory(dir.path("bad.txt"), bad), Error);
    EXPECT_FALSE(std::ifstream(dir.path("bad.txt")).good());
  }
}
