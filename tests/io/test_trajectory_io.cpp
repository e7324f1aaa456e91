#include "ellreloc/error.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/trajectory.hpp"

#include "fixtures/data_dir.hpp"
#include "fixtures/random_geometry.hpp"
#include "fixtures/temp_dir.hpp"

#include <gtest/gtest.h>

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
