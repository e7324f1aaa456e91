#include "ellreloc/sim/writer.hpp"

#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>
#include <sstream>

#include "ellreloc/error.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/image_codec.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/io/rgbd.hpp"
#include "ellreloc/io/trajectory.hpp"
#include "ellreloc/sim/render.hpp"
#include "ellreloc/sim/truth.hpp"

namespace ellreloc::sim {

namespace {

std::string stamp(double t) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6f", t);
  return buf;
}

/// A colour per instance, shaded by depth; floor and furniture grey.
void writeRgb(const std::string& path, const RenderedFrame& f) {
  cv::Mat img(f.height, f.width, CV_8UC3);
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const int id = f.instanceAt(x, y);
      const float z = f.depthAt(x, y);
      const double shade = z > 0 ? std::clamp(1.2 - 0.15 * z, 0.3, 1.0) : 0.0;
      cv::Vec3b c(170, 170, 170);
      if (id >= 0)
        c = cv::Vec3b(static_cast<uint8_t>(60 + (id * 97) % 196), static_cast<uint8_t>(60 + (id * 57) % 196),
                      static_cast<uint8_t>(60 + (id * 151) % 196));
      img.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uint8_t>(c[0] * shade), static_cast<uint8_t>(c[1] * shade),
                                          static_cast<uint8_t>(c[2] * shade));
    }
  io::writeFileAtomically(path, io::encodePng(img.data, img.cols, img.rows, io::PixelFormat::Bgr8, img.step));
}

void makeDirs(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw FileError(dir + ": cannot create directory: " + ec.message());
}

}  // namespace

SimulationSummary writeSimulation(const std::string& dir, const SimulationOptions& opt) {
  if (!opt.camera.isValid()) throw Error("simulate: invalid camera intrinsics");
  if (opt.mapping_frames < 1 || opt.query_frames < 1) throw Error("simulate: frame counts must be positive");
  SimulationSummary summary;
  const Scene scene = makeScene(opt.preset, opt.seed);
  const NoiseModel noise = NoiseModel::preset(opt.noise);
  std::mt19937_64 rng(opt.seed * 7919 + 17);
  for (const char* sub : {"", "/mapping/rgb", "/mapping/depth", "/query/rgb"}) makeDirs(dir + sub);
  auto wrote = [&](const std::string& rel) { summary.files.push_back(rel); };

  io::writeCamera(dir + "/camera.yaml", opt.camera);
  wrote("camera.yaml");
  const ObjectMap truth = scene.groundTruthMap();
  io::writeMap(dir + "/map_groundtruth.json", truth);
  wrote("map_groundtruth.json");
  io::writeMap(dir + "/map_perturbed.json", perturbMap(truth, noise, opt.seed + 1));
  wrote("map_perturbed.json");
  summary.objects = static_cast<int>(scene.objects.size());

  // Mapping sequence: depth, masks, poses.
  std::ostringstream assoc;
  std::vector<io::StampedPose> mapping_poses;
  std::vector<DetectionFrame> mapping_dets, mapping_truth;
  const auto mapping = mappingTrajectory(scene, opt.mapping_frames);
  for (size_t i = 0; i < mapping.size(); ++i) {
    const double t = 1000.0 + static_cast<double>(i) / 30.0;
    const std::string name = stamp(t) + ".png";
    const RenderedFrame f = render(scene, opt.camera, mapping[i]);
    io::writeDepthPng(dir + "/mapping/depth/" + name, noisyDepth(f, noise, rng));
    wrote("mapping/depth/" + name);
    if (opt.write_rgb) {
      writeRgb(dir + "/mapping/rgb/" + name, f);
      wrote("mapping/rgb/" + name);
    }
    assoc << stamp(t) << " rgb/" << name << " " << stamp(t) << " depth/" << name << "\n";
    mapping_poses.push_back({t, mapping[i], stamp(t)});
    mapping_dets.push_back({"rgb/" + name, detect(scene, f, noise, rng), {}});
    mapping_truth.push_back(
        {"rgb/" + name, detectionTruth(scene, f, opt.camera, mapping[i], mapping_dets.back().detections), {}});
  }
  io::writeFileAtomically(dir + "/mapping/associations.txt", assoc.str());
  wrote("mapping/associations.txt");
  io::writeTumTrajectory(dir + "/mapping/trajectory.txt", mapping_poses);
  wrote("mapping/trajectory.txt");
  io::writeDetections(dir + "/mapping/detections.json", mapping_dets);
  wrote("mapping/detections.json");
  io::writeDetections(dir + "/mapping/ellipse_truth.json", mapping_truth);
  wrote("mapping/ellipse_truth.json");
  summary.mapping_frames = static_cast<int>(mapping.size());

  // Query sequence: detections and ground truth.
  std::vector<io::StampedPose> query_poses;
  std::vector<DetectionFrame> query_dets, query_truth;
  const auto query = queryTrajectory(scene, opt.query_frames, opt.seed + 2);
  for (size_t i = 0; i < query.size(); ++i) {
    const double t = 2000.0 + 0.5 * static_cast<double>(i);
    const std::string name = stamp(t) + ".png";
    const RenderedFrame f = render(scene, opt.camera, query[i]);
    if (opt.write_rgb) {
      writeRgb(dir + "/query/rgb/" + name, f);
      wrote("query/rgb/" + name);
    }
    query_poses.push_back({t, query[i], stamp(t)});
    query_dets.push_back(
        {"rgb/" + name, detect(scene, f, noise, rng), keypoints(scene, f, opt.camera, query[i], noise, rng)});
    query_truth.push_back(
        {"rgb/" + name, detectionTruth(scene, f, opt.camera, query[i], query_dets.back().detections), {}});
    summary.query_detections += static_cast<int>(query_dets.back().detections.size());
  }
  io::writeDetections(dir + "/query/detections.json", query_dets);
  wrote("query/detections.json");
  io::writeDetections(dir + "/query/ellipse_truth.json", query_truth);
  wrote("query/ellipse_truth.json");
  io::writeTumTrajectory(dir + "/query/groundtruth.txt", query_poses);
  wrote("query/groundtruth.txt");
  summary.query_frames = static_cast<int>(query.size());
  return summary;
}

}  // namespace ellreloc::sim
