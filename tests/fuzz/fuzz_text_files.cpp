// The readers that take paths: camera YAML and JSON, TUM trajectories, association files.
#include <algorithm>
#include <cmath>

#include "ellreloc/error.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/rgbd.hpp"
#include "ellreloc/io/trajectory.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ellreloc;
  for (const char* ext : {".yaml", ".json"}) {
    try {
      const Intrinsics K = io::readCamera(fuzz::writeScratch(data, size, ext));
      FUZZ_CHECK(K.isValid());  // a camera is valid or an error
      // A lens is one that can be undone over its image, or an error; a pinhole pixel found for a
      // raw one is finite and the lens maps it back.
      const Lens lens = io::readLens(fuzz::writeScratch(data, size, ext));
      FUZZ_CHECK(lens.whyNotUsable().empty());
      for (const Eigen::Vector2d raw : {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(K.width - 0.5, K.height - 0.5),
                                        Eigen::Vector2d(K.cx, K.cy), Eigen::Vector2d(0.0, K.height / 2.0)})
        if (const std::optional<Eigen::Vector2d> u = lens.undistortPixel(raw)) {
          FUZZ_CHECK(u->allFinite());
          // Converged to 1e-9 in normalised coordinates, then scaled by the focal lengths.
          const double scale = K.fx + K.fy + std::abs(K.cx) + std::abs(K.cy) + raw.norm();
          FUZZ_CHECK((lens.distortion.distortPixel(K, *u) - raw).norm() <= 1e-8 * scale);
        }
    } catch (const Error&) {
    }
  }
  const std::string txt = fuzz::writeScratch(data, size, ".txt");
  try {
    const std::vector<io::StampedPose> poses = io::readTumTrajectory(txt);
    for (const io::StampedPose& p : poses) FUZZ_CHECK(p.pose.isValid() && std::isfinite(p.timestamp));
    // What was read is written back with the same timestamp texts, and reads back the same.
    const std::string again = fuzz::writeScratch(nullptr, 0, ".out.txt");
    io::writeTumTrajectory(again, poses);
    const std::vector<io::StampedPose> back = io::readTumTrajectory(again);
    FUZZ_CHECK(back.size() == poses.size());
    for (size_t i = 0; i < back.size(); ++i)
      FUZZ_CHECK(back[i].stamp == poses[i].stamp && back[i].timestamp == poses[i].timestamp);
  } catch (const Error&) {
  }
  try {
    // Each line is found by its colour image (that line or a later one naming the same image),
    // and by its time alone the line nearest in time, as reading every line finds it.
    const std::vector<io::Association> lines = io::readAssociations(txt);
    const io::AssociationIndex index(lines);
    for (const io::Association& a : lines) {
      const io::Association* named = index.find(a.rgb_path, std::nullopt);
      FUZZ_CHECK(named && named->rgb_path == a.rgb_path);
      const double t = a.rgb_time + 0.007;  // within the 0.02 s tolerance of this line at least
      double nearest = INFINITY;
      for (const io::Association& b : lines) nearest = std::min(nearest, std::abs(b.rgb_time - t));
      const io::Association* timed = index.find("/no such image", t);
      FUZZ_CHECK(nearest > 0.02 || (timed && std::abs(timed->rgb_time - t) == nearest));
    }
  } catch (const Error&) {
  }
  return 0;
}
