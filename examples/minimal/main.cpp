// The library calls behind relocalization, for one frame.
//   ellreloc_minimal                                 a built-in scene of eight objects
//   ellreloc_minimal camera.yaml map.json detections.json   the first frame of your data
#include <cstdio>
#include <ellreloc/core.hpp>
#include <ellreloc/io/camera.hpp>
#include <ellreloc/io/detections.hpp>
#include <ellreloc/io/map.hpp>
#include <ellreloc/pose/object_relocalizer.hpp>

using namespace ellreloc;

int main(int argc, char** argv) try {
  if (argc != 1 && argc != 4) {
    std::fprintf(stderr, "usage: %s [camera.yaml map.json detections.json]\n", argv[0]);
    return 2;
  }
  Intrinsics K(525.0, 525.0, 319.5, 239.5, 640, 480);
  ObjectMap map;
  std::vector<Observation> observations;
  if (argc == 4) {
    K = io::readCamera(argv[1]);
    map = io::readMap(argv[2]);
    for (const Detection& d : io::readDetections(argv[3]).at(0).detections)
      if (auto o = observationFromBox(d.category_id, d.score, d.bbox, K.width, K.height)) observations.push_back(*o);
  } else {
    // Objects on and around a desk (world z up), COCO ids: tv 62, keyboard 66, cup 41, book 73,
    // bottle 39, chair 56, laptop 63, mouse 64.
    const auto yaw = [](double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); };
    const std::pair<int, Ellipsoid> desk[] = {{62, {{0.0, 0.3, 1.0}, {0.28, 0.04, 0.2}, yaw(0.1)}},
                                              {66, {{0.0, 0.0, 0.77}, {0.22, 0.07, 0.015}, yaw(-0.05)}},
                                              {41, {{0.35, 0.05, 0.8}, {0.04, 0.04, 0.05}, yaw(0)}},
                                              {73, {{-0.4, 0.1, 0.77}, {0.12, 0.09, 0.02}, yaw(0.6)}},
                                              {39, {{0.5, 0.35, 0.86}, {0.035, 0.035, 0.11}, yaw(0)}},
                                              {56, {{0.1, -0.6, 0.45}, {0.25, 0.25, 0.45}, yaw(0.3)}},
                                              {63, {{-0.6, 0.35, 0.85}, {0.17, 0.12, 0.1}, yaw(-0.4)}},
                                              {64, {{0.3, -0.1, 0.77}, {0.03, 0.05, 0.02}, yaw(0.2)}}};
    for (const auto& [category, e] : desk)
      map.objects.push_back({static_cast<int>(map.objects.size()), category, "", e});
    // What a detector sees from a camera 1.5 m in front of the desk: one box per object.
    const Eigen::Vector3d eye(-0.4, -1.5, 1.4);
    const Pose truth = Pose::lookAt(eye, eye + Eigen::Vector3d(0.3, 1.4, -0.6));
    for (const MapObject& m : map.objects)
      if (const Projection p = project(m.ellipsoid, K, truth))
        observations.push_back(*observationFromBox(m.category, 0.9, p.ellipse.boundingBox(), K.width, K.height));
    std::printf("true camera centre: %.3f %.3f %.3f\n", truth.center()(0), truth.center()(1), truth.center()(2));
  }

  const ObjectRelocalizer relocalizer(map, K);
  const RelocalizationResult r = relocalizer.relocalize(observations);
  if (r.status != RelocalizationStatus::Success) {
    std::printf("not relocalized: %s (%s)\n", toString(r.status), r.reason.c_str());
    return 1;
  }
  const Eigen::Vector3d c = r.pose.center();
  std::printf("camera centre:      %.3f %.3f %.3f\n", c(0), c(1), c(2));
  std::printf("%zu of %zu observations matched, %ld hypotheses, %.2f ms\n", r.inliers.size(), observations.size(),
              r.hypotheses, r.time_ms);
  for (const ObjectCorrespondence& m : r.inliers)
    std::printf("  observation %d -> object %d (IoU %.2f)\n", m.observation, map.objects[m.object].id, m.overlap);
  return 0;
} catch (const Error& e) {
  std::fprintf(stderr, "ellreloc_minimal: %s\n", e.what());
  return 2;
}
