// The library calls behind `ellreloc relocalize`, for one frame:
//   ellreloc_minimal camera.yaml map.json detections.json [frame index, default 0]
#include <cstdio>
#include <cstdlib>
#include <ellreloc/error.hpp>
#include <ellreloc/io/camera.hpp>
#include <ellreloc/io/detections.hpp>
#include <ellreloc/io/map.hpp>
#include <ellreloc/observe/observe.hpp>
#include <ellreloc/pose/object_relocalizer.hpp>

using namespace ellreloc;

int main(int argc, char** argv) try {
  if (argc != 4 && argc != 5) {
    std::fprintf(stderr, "usage: %s camera.yaml map.json detections.json [frame index]\n", argv[0]);
    return 2;
  }
  const Intrinsics K = io::readCamera(argv[1]);
  const ObjectMap map = io::readMap(argv[2]);
  const std::vector<DetectionFrame> frames = io::readDetections(argv[3]);
  const size_t index = argc == 5 ? std::strtoul(argv[4], nullptr, 10) : 0;
  if (index >= frames.size()) throw Error(std::string(argv[3]) + ": no frame " + std::to_string(index));

  // Detections (box, category, score, optional mask) -> observation ellipses.
  const std::vector<Observation> observations = observeDetections(frames[index].detections, K.width, K.height);

  // One relocalizer per map; relocalize() is const and thread-safe.
  const ObjectRelocalizer relocalizer(map, K);
  const RelocalizationResult r = relocalizer.relocalize(observations);
  if (r.status != RelocalizationStatus::Success) {
    std::printf("%s: not relocalized: %s (%s)\n", frames[index].file_name.c_str(), toString(r.status),
                r.reason.c_str());
    return 1;
  }
  const Eigen::Vector3d c = r.pose.center();  // r.pose is world->camera
  std::printf("%s: camera centre %.3f %.3f %.3f, %zu of %zu observations matched, %.2f ms\n",
              frames[index].file_name.c_str(), c(0), c(1), c(2), r.inliers.size(), observations.size(), r.time_ms);
  for (const ObjectCorrespondence& m : r.inliers)
    std::printf("  observation %d -> object %d (overlap %.2f)\n", m.observation, map.objects[m.object].id, m.overlap);
  // Other answers the frame allows (look-alike objects), cheapest first: the poses a system with
  // points would check next if its check of r.pose failed.
  for (const ScoredPose& other : r.alternatives) {
    const Eigen::Vector3d o = other.pose.center();
    std::printf("  or camera centre %.3f %.3f %.3f (cost %.2f more)\n", o(0), o(1), o(2), other.cost - r.cost);
  }
  return 0;
} catch (const Error& e) {
  std::fprintf(stderr, "ellreloc_minimal: %s\n", e.what());
  return 2;
}
