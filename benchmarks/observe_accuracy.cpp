// Which ellipse lands closest to the true projected ellipsoid? Rendered objects (thin boxes seen
// roughly face-on, boxes, cylinders, chairs built from boxes) with +-2 px boundary noise; some
// cut by the image border. Error = W2(fit, truth) / sqrt(a b) of the truth, the projection of
// the ellipsoid inscribed in the object's oriented bounding cuboid. Medians, split by the
// regular verdict and by truncation, and over all masks.
// Run: ./build/benchmarks/observe_accuracy
#include <algorithm>
#include <cstdio>
#include <map>
#include <random>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/core/statistics.hpp"
#include "ellreloc/observe/ellipse_fit.hpp"
#include "ellreloc/observe/observe.hpp"
#include "fixtures/mask_shapes.hpp"

using namespace ellreloc;

namespace {

const Intrinsics kK(525.0, 525.0, 319.5, 239.5, 640, 480);

struct Part {  // a convex part: its surface points
  std::vector<Eigen::Vector3d> points;
};

std::vector<Eigen::Vector3d> cuboid(const Eigen::Vector3d& c, const Eigen::Vector3d& half, const Eigen::Matrix3d& R) {
  std::vector<Eigen::Vector3d> p;
  for (int k = 0; k < 8; ++k)
    p.push_back(
        c + R * Eigen::Vector3d((k & 1 ? 1 : -1) * half(0), (k & 2 ? 1 : -1) * half(1), (k & 4 ? 1 : -1) * half(2)));
  return p;
}

std::vector<Eigen::Vector3d> cylinder(const Eigen::Vector3d& c, double r, double h, const Eigen::Matrix3d& R) {
  std::vector<Eigen::Vector3d> p;
  for (int k = 0; k < 48; ++k) {
    const double a = 2 * M_PI * k / 48;
    for (double z : {-h / 2, h / 2}) p.push_back(c + R * Eigen::Vector3d(r * std::cos(a), r * std::sin(a), z));
  }
  return p;
}

/// Rasterises the union of the parts' projected convex hulls; false if a part is behind.
bool render(const std::vector<Part>& parts, const Pose& pose, BinaryMask* mask) {
  *mask = BinaryMask(kK.height, kK.width);
  for (const Part& part : parts) {
    std::vector<Eigen::Vector2d> img;
    for (const auto& x : part.points) {
      const Eigen::Vector3d xc = pose.transform(x);
      if (xc(2) < 0.05) return false;
      img.push_back(kK.project(xc));
    }
    test::addConvexHull(img, *mask);
  }
  return true;
}

double medianOrNan(std::vector<double> v) { return ellreloc::median(std::move(v), NAN); }

}  // namespace

int main(int argc, char**) {
  if (argc > 1) {
    std::fprintf(stderr, "usage: observe_accuracy  (no arguments: 2,000 rendered masks, a Markdown table)\n");
    return 2;
  }
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // errors[group][method]
  std::map<std::string, std::map<std::string, std::vector<double>>> errors;
  int rendered = 0;
  while (rendered < 2000) {
    const int kind = rendered % 4;  // 0 thin box, 1 box, 2 cylinder, 3 chair
    const double yaw = 2 * M_PI * u(rng);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    std::vector<Part> parts;
    Eigen::Vector3d half;  // oriented bounding cuboid (object frame = R), centred at the origin
    if (kind == 0) {
      half = Eigen::Vector3d(0.15 + 0.15 * u(rng), 0.01 + 0.01 * u(rng), 0.1 + 0.12 * u(rng));
      parts.push_back({cuboid(Eigen::Vector3d::Zero(), half, R)});
    } else if (kind == 1) {
      half = Eigen::Vector3d(0.06 + 0.1 * u(rng), 0.06 + 0.1 * u(rng), 0.05 + 0.1 * u(rng));
      parts.push_back({cuboid(Eigen::Vector3d::Zero(), half, R)});
    } else if (kind == 2) {
      const double r = 0.03 + 0.04 * u(rng), h = 0.08 + 0.2 * u(rng);
      half = Eigen::Vector3d(r, r, h / 2);
      parts.push_back({cylinder(Eigen::Vector3d::Zero(), r, h, R)});
    } else {  // chair: seat, back, four legs
      const double w = 0.22, d = 0.22, hs = 0.45, hb = 0.45;
      half = Eigen::Vector3d(w, d, (hs + hb) / 2);
      const double z0 = -half(2);
      parts.push_back({cuboid(R * Eigen::Vector3d(0, 0, z0 + hs), {w, d, 0.02}, R)});
      parts.push_back({cuboid(R * Eigen::Vector3d(0, d - 0.02, z0 + hs + hb / 2), {w, 0.02, hb / 2}, R)});
      for (int k = 0; k < 4; ++k)
        parts.push_back(
            {cuboid(R * Eigen::Vector3d((k & 1 ? 1 : -1) * (w - 0.02), (k & 2 ? 1 : -1) * (d - 0.02), z0 + hs / 2),
                    {0.02, 0.02, hs / 2}, R)});
    }
    // Camera: 0.8-3 m away; thin boxes are seen within 35 degrees of their face normal.
    const double dist = 0.8 + 2.2 * u(rng);
    const double az = kind == 0 ? yaw + M_PI / 2 + (u(rng) - 0.5) * 1.2 : 2 * M_PI * u(rng);
    const double el = (u(rng) - 0.3) * 0.8;
    const Eigen::Vector3d centre =
        dist * Eigen::Vector3d(std::cos(az) * std::cos(el), std::sin(az) * std::cos(el), std::sin(el));
    // Look near the object, sometimes far enough off to cut it at the image border.
    const Eigen::Vector3d target =
        Eigen::Vector3d(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5) * (u(rng) < 0.2 ? 0.9 : 0.2) * dist;
    const Pose pose = Pose::lookAt(centre, target);
    const Projection truth = project(Ellipsoid(Eigen::Vector3d::Zero(), half, R), kK, pose);
    BinaryMask mask;
    if (!truth || !render(parts, pose, &mask) || mask.count() < 200) continue;
    test::addBoundaryNoise(mask, rng, 0.5);  // +-1 px
    test::addBoundaryNoise(mask, rng, 0.5);  // up to +-2 px
    ++rendered;
    const RleMask rle = encodeMask(mask);
    const auto moments = rleMoments(rle);
    if (!moments) continue;
    const RegularVerdict verdict = testRegularMask(rle);
    const double scale = std::sqrt(truth.ellipse.axes().prod());
    const std::string group =
        std::string(verdict.regular ? "regular" : "irregular") + (verdict.touches_border ? ", truncated" : "");
    // Each mask under its verdict's group; every mask also under "all" for the methods that
    // give every mask an ellipse (the quadrilateral fit needs four corners).
    auto record = [&](const std::string& method, const std::optional<Ellipse>& e) {
      if (!e || !e->isValid()) return;
      const double error = wasserstein2(*e, truth.ellipse) / scale;
      errors[group][method].push_back(error);
      if (method != "quadrilateral") errors["all"][method].push_back(error);
    };
    record("box-inscribed", Ellipse::inscribedInBox(moments->bounds));
    record("moments", fitMaskEllipse(rle, MaskFitMethod::Moments, &verdict));
    record("direct (outline)", fitMaskEllipse(rle, MaskFitMethod::Direct, &verdict));
    record("hull", fitMaskEllipse(rle, MaskFitMethod::Hull, &verdict));
    if (verdict.quad_vertices == 4)
      record("quadrilateral", fitMaskEllipse(rle, MaskFitMethod::Quadrilateral, &verdict));
    Detection det;
    det.bbox = moments->bounds;
    det.mask = rle;
    ObserveOptions paper;
    paper.policy = ObservationPolicy::Paper;
    if (const ObserveResult r = observeDetection(det, kK.width, kK.height, paper); r.observation)
      record("paper policy", r.observation->ellipse);
    if (const ObserveResult r = observeDetection(det, kK.width, kK.height); r.observation)
      record("default (solid policy)", r.observation->ellipse);
  }
  std::printf(
      "| masks | n | box-inscribed | moments | direct (outline) | hull | quadrilateral | paper policy | "
      "default (solid policy) |\n|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& [group, methods] : errors) {
    std::printf("| %s | %zu |", group.c_str(), methods.at("box-inscribed").size());
    for (const char* m : {"box-inscribed", "moments", "direct (outline)", "hull", "quadrilateral", "paper policy",
                          "default (solid policy)"}) {
      const auto it = methods.find(m);
      if (it == methods.end())
        std::printf(" - |");
      else
        std::printf(" %.3f |", medianOrNan(it->second));
    }
    std::printf("\n");
  }
  return 0;
}
