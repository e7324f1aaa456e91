#include "ellreloc/sim/noise.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "draw.hpp"
#include "ellreloc/core/mask.hpp"

namespace ellreloc::sim {

NoiseModel NoiseModel::preset(NoiseLevel level) {
  NoiseModel m;
  if (level == NoiseLevel::Realistic) {
    m.mask_boundary_px = 2;
    m.box_jitter_px = 2.0;
    m.miss_rate = 0.1;
    m.false_positives = 0.3;
    m.label_confusion = 0.03;
    m.depth_sigma_at_2m = 0.01;
    m.keypoint_sigma_px = 1.0;
    m.keypoint_outliers = 0.2;
    m.map_centre_sigma = 0.02;
    m.map_axis_sigma = 0.08;
    m.map_yaw_sigma_deg = 4.0;
  } else if (level == NoiseLevel::Hard) {
    m.mask_boundary_px = 3;
    m.box_jitter_px = 5.0;
    m.miss_rate = 0.25;
    m.false_positives = 1.0;
    m.label_confusion = 0.1;
    m.depth_sigma_at_2m = 0.03;
    m.keypoint_sigma_px = 2.0;
    m.keypoint_outliers = 0.4;
    m.map_centre_sigma = 0.05;
    m.map_axis_sigma = 0.15;
    m.map_yaw_sigma_deg = 10.0;
  }
  return m;
}

const char* toString(NoiseLevel level) {
  switch (level) {
    case NoiseLevel::None:
      return "none";
    case NoiseLevel::Realistic:
      return "realistic";
    case NoiseLevel::Hard:
      return "hard";
  }
  return "none";
}

bool parseNoiseLevel(const std::string& name, NoiseLevel* level) {
  for (NoiseLevel l : {NoiseLevel::None, NoiseLevel::Realistic, NoiseLevel::Hard})
    if (name == toString(l)) {
      *level = l;
      return true;
    }
  return false;
}

namespace {

/// Erodes or dilates a mask by r pixels (a disc), r drawn in [1, max_px]. The work is done on
/// the mask's box grown by r: a disc of radius r reaches no pixel beyond it, and where the box
/// meets the image border the crop's border is the image's, so the result is the whole image's.
RleMask morphNoise(const RleMask& rle, int max_px, std::mt19937_64& rng) {
  if (!rle.isConsistent() || max_px <= 0) return rle;
  const int r = std::uniform_int_distribution<int>(1, max_px)(rng);
  const bool dilate = std::bernoulli_distribution(0.5)(rng);
  std::optional<BinaryMask> m = decodeMaskCrop(rle, r);
  if (!m) return emptyRle(rle.height, rle.width);  // no pixel
  cv::Mat img(m->height, m->width, CV_8U, m->data.data());
  const cv::Mat disc = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1));
  cv::Mat out;
  if (dilate)
    cv::dilate(img, out, disc);
  else
    cv::erode(img, out, disc);
  std::copy(out.data, out.data + m->data.size(), m->data.begin());
  return encodeMask(*m);
}

/// Toggles round(rate x area) pixels drawn uniformly in the mask's box grown by 2 pixels:
/// holes inside the object and specks around it, as a segmentation network's pixel errors.
RleMask flipPixels(const RleMask& rle, double rate, std::mt19937_64& rng) {
  const auto moments = rleMoments(rle);
  auto m = decodeMaskCrop(rle, 2);  // the box grown by 2 pixels, cut to the image
  if (!m || !moments || !(rate > 0.0)) return rle;
  std::uniform_int_distribution<int> ux(m->x0, m->x0 + m->width - 1), uy(m->y0, m->y0 + m->height - 1);
  for (long k = std::lround(rate * moments->area); k > 0; --k) {
    const int y = uy(rng);  // drawn before x: see drawLastFirst
    uint8_t& px = m->at(ux(rng) - m->x0, y - m->y0);
    px = px ? 0 : 1;
  }
  return encodeMask(*m);
}

}  // namespace

std::vector<Detection> detect(const Scene& scene, const RenderedFrame& frame, const NoiseModel& noise,
                              std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Detection> out;
  const Box image(-0.5, -0.5, frame.width - 0.5, frame.height - 0.5);
  for (size_t j = 0; j < scene.objects.size(); ++j) {
    if (frame.visible_pixels[j] < noise.min_visible_pixels || u(rng) < noise.miss_rate) continue;
    Detection d;
    d.category_id = scene.objects[j].category;
    if (u(rng) < noise.label_confusion)
      d.category_id = scene.objects[(j + 1 + static_cast<size_t>(u(rng) * 7)) % scene.objects.size()].category;
    d.score = std::clamp(0.6 + 0.35 * u(rng), 0.0, 1.0);
    d.mask = noise.mask_boundary_px > 0 ? morphNoise(frame.masks[j], noise.mask_boundary_px, rng) : frame.masks[j];
    if (noise.mask_flip_rate > 0.0) d.mask = flipPixels(*d.mask, noise.mask_flip_rate, rng);
    const auto moments = rleMoments(*d.mask);
    if (!moments) continue;  // eroded away
    const Box& b = moments->bounds;
    const Eigen::Vector4d jitter = detail::drawLastFirst<4>([&] { return noise.box_jitter_px * g(rng); });
    d.bbox = Box(b.x1 + jitter(0), b.y1 + jitter(1), b.x2 + jitter(2), b.y2 + jitter(3)).intersection(image);
    if (!(d.bbox.width() > 2) || !(d.bbox.height() > 2)) continue;
    d.object_id = scene.objects[j].id;
    out.push_back(std::move(d));
  }
  // False positives: random boxes with blob masks of a random category.
  std::poisson_distribution<int> fp(noise.false_positives);
  for (int k = noise.false_positives > 0 ? fp(rng) : 0; k > 0; --k) {
    const double w = 20 + 100 * u(rng), h = 20 + 100 * u(rng);
    const double x = (frame.width - w) * u(rng), y = (frame.height - h) * u(rng);
    const Ellipse e({x + w / 2, y + h / 2}, {w / 2, h / 2}, 0.0);
    const int xa = static_cast<int>(x), xb = std::min(static_cast<int>(x + w), frame.width);
    const int ya = static_cast<int>(y), yb = std::min(static_cast<int>(y + h), frame.height);
    BinaryMask m(std::max(yb - ya, 0), std::max(xb - xa, 0));  // a crop of the image: the blob's box
    m.x0 = xa, m.y0 = ya, m.image_width = frame.width, m.image_height = frame.height;
    for (int yy = ya; yy < yb; ++yy)
      for (int xx = xa; xx < xb; ++xx) m.at(xx - xa, yy - ya) = e.contains({double(xx), double(yy)});
    Detection d;
    d.category_id = scene.objects[static_cast<size_t>(u(rng) * scene.objects.size()) % scene.objects.size()].category;
    d.score = 0.3 + 0.4 * u(rng);
    d.mask = encodeMask(m);
    const auto moments = rleMoments(*d.mask);
    if (!moments) continue;
    d.bbox = moments->bounds;
    out.push_back(std::move(d));
  }
  return out;
}

std::vector<Keypoint> keypoints(const Scene& scene, const RenderedFrame& frame, const Intrinsics& K, const Pose& pose,
                                const NoiseModel& noise, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Keypoint> out;
  const int n = static_cast<int>(scene.points.size());
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d x = pose.transform(scene.points[i]);
    if (x(2) < 0.1) continue;
    const Eigen::Vector2d uv = K.project(x);
    const int px = static_cast<int>(std::lround(uv(0))), py = static_cast<int>(std::lround(uv(1)));
    if (px < 0 || py < 0 || px >= frame.width || py >= frame.height) continue;
    const float z = frame.depthAt(px, py);
    if (z > 0 && x(2) > z + 0.03) continue;  // hidden behind another surface
    Keypoint k;
    k.point_index = i;
    k.uv = uv + noise.keypoint_sigma_px * detail::drawLastFirst<2>([&] { return g(rng); });
    if (u(rng) < noise.keypoint_outliers) k.point_index = static_cast<int>(u(rng) * n) % n;  // a wrong match
    out.push_back(k);
  }
  return out;
}

DepthImage noisyDepth(const RenderedFrame& frame, const NoiseModel& noise, std::mt19937_64& rng) {
  DepthImage d;
  d.width = frame.width;
  d.height = frame.height;
  d.metres = frame.depth;
  if (noise.depth_sigma_at_2m > 0) {
    std::normal_distribution<double> g(0.0, 1.0);
    for (float& z : d.metres)
      if (z > 0) z = std::max(0.0f, static_cast<float>(z + noise.depth_sigma_at_2m * (z / 2.0) * (z / 2.0) * g(rng)));
  }
  return d;
}

ObjectMap perturbMap(const ObjectMap& map, const NoiseModel& noise, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  ObjectMap out = map;
  for (MapObject& o : out.objects) {
    const Ellipsoid& e = o.ellipsoid;
    const Eigen::Vector3d c = e.center() + noise.map_centre_sigma * detail::drawLastFirst<3>([&] { return g(rng); });
    Eigen::Vector3d axes = e.axes();
    for (int k = 0; k < 3; ++k) axes(k) *= std::max(0.3, 1.0 + noise.map_axis_sigma * g(rng));
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(noise.map_yaw_sigma_deg * M_PI / 180.0 * g(rng), Eigen::Vector3d::UnitZ())
            .toRotationMatrix() *
        e.rotation();
    o.ellipsoid = Ellipsoid(c, axes, R);
  }
  return out;
}

}  // namespace ellreloc::sim
