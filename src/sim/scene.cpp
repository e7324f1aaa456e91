#include "ellreloc/sim/scene.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "draw.hpp"

namespace ellreloc::sim {

namespace {

Eigen::Matrix3d yaw(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

/// Categories with plausible sizes (half-extents, metres) and shapes.
enum class Kind { ThinBox, Box, Cylinder, Chair, Teddy };
struct Category {
  int id;
  const char* label;
  Kind kind;
  Eigen::Vector3d half;  // nominal half-extents (x along the object's width, z up)
};
const Category kCategories[] = {
    {62, "tv", Kind::ThinBox, {0.28, 0.025, 0.19}},     {63, "laptop", Kind::ThinBox, {0.17, 0.12, 0.012}},
    {73, "book", Kind::ThinBox, {0.1, 0.075, 0.02}},    {66, "keyboard", Kind::ThinBox, {0.22, 0.07, 0.015}},
    {64, "mouse", Kind::Box, {0.03, 0.055, 0.018}},     {24, "backpack", Kind::Box, {0.16, 0.1, 0.22}},
    {41, "cup", Kind::Cylinder, {0.04, 0.04, 0.05}},    {39, "bottle", Kind::Cylinder, {0.035, 0.035, 0.12}},
    {75, "vase", Kind::Cylinder, {0.06, 0.06, 0.13}},   {56, "chair", Kind::Chair, {0.23, 0.23, 0.45}},
    {77, "teddy bear", Kind::Teddy, {0.12, 0.1, 0.16}}, {74, "clock", Kind::Cylinder, {0.12, 0.12, 0.025}},
};

const Category& categoryById(int id) {
  for (const Category& c : kCategories)
    if (c.id == id) return c;
  return kCategories[0];
}

Primitive box(const Eigen::Vector3d& c, const Eigen::Vector3d& half, const Eigen::Matrix3d& R) {
  return {PrimitiveShape::Box, c, half, R};
}

/// An object of a category standing on a surface at height `z` at (x, y) with yaw `a`,
/// its size scaled by s per axis (0.8-1.2).
SimObject makeObject(int id, const Category& cat, double x, double y, double z, double a, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> s(0.85, 1.15);
  const Eigen::Vector3d half = cat.half.cwiseProduct(detail::drawLastFirst<3>([&] { return s(rng); }));
  const Eigen::Matrix3d R = yaw(a);
  SimObject o;
  o.id = id;
  o.category = cat.id;
  o.label = cat.label;
  o.box_rotation = R;
  o.box_half = half;
  o.box_center = Eigen::Vector3d(x, y, z + half(2));
  const Eigen::Vector3d c = o.box_center;
  switch (cat.kind) {
    case Kind::ThinBox:
    case Kind::Box:
      o.parts.push_back(box(c, half, R));
      break;
    case Kind::Cylinder: {
      const double r = std::min(half(0), half(1));
      o.box_half = Eigen::Vector3d(r, r, half(2));
      o.parts.push_back({PrimitiveShape::Cylinder, c, o.box_half, R});
      break;
    }
    case Kind::Chair: {  // seat, back, four legs: an irregular silhouette
      const Eigen::Vector3d base(x, y, z);
      const auto at = [&](const Eigen::Vector3d& local) { return Eigen::Vector3d(base + R * local); };
      const double w = half(0), d = half(1), top = 2.0 * half(2), seat = 0.48 * top;
      o.parts.push_back(box(at({0, 0, seat}), {w, d, 0.025}, R));
      o.parts.push_back(box(at({0, d - 0.02, 0.5 * (seat + top)}), {w, 0.02, 0.5 * (top - seat)}, R));
      for (int k = 0; k < 4; ++k)
        o.parts.push_back(box(at({(k & 1 ? 1 : -1) * (w - 0.025), (k & 2 ? 1 : -1) * (d - 0.025), 0.5 * seat}),
                              {0.02, 0.02, 0.5 * seat}, R));
      break;
    }
    case Kind::Teddy: {  // body, head, two arms
      const Eigen::Vector3d base(x, y, z);
      const auto at = [&](const Eigen::Vector3d& local) { return Eigen::Vector3d(base + R * local); };
      const double h = 2.0 * half(2);
      o.parts.push_back(box(at({0, 0, 0.3 * h}), {0.75 * half(0), 0.9 * half(1), 0.3 * h}, R));
      o.parts.push_back({PrimitiveShape::Ellipsoid, at({0, 0, 0.8 * h}), {0.5 * half(0), 0.5 * half(0), 0.2 * h}, R});
      for (int k = -1; k <= 1; k += 2)
        o.parts.push_back(box(at({k * 0.85 * half(0), 0, 0.4 * h}), {0.15 * half(0), 0.3 * half(1), 0.15 * h}, R));
      break;
    }
  }
  return o;
}

/// A point on the surface of a primitive (uniform over the parameters, good enough for map points).
Eigen::Vector3d surfacePoint(const Primitive& p, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Vector3d l;
  if (p.shape == PrimitiveShape::Box) {
    l = detail::drawLastFirst<3>([&] { return u(rng); });
    const int face = static_cast<int>((u(rng) + 1.0) * 1.5) % 3;
    l(face) = l(face) >= 0 ? 1.0 : -1.0;
    l = l.cwiseProduct(p.half);
  } else if (p.shape == PrimitiveShape::Cylinder) {
    const double a = M_PI * u(rng);
    l = Eigen::Vector3d(p.half(0) * std::cos(a), p.half(0) * std::sin(a), p.half(2) * u(rng));  // one draw
  } else {
    l = detail::drawLastFirst<3>([&] { return u(rng); }).normalized().cwiseProduct(p.half);
  }
  return p.center + p.rotation * l;
}

}  // namespace

const char* toString(ScenePreset preset) {
  switch (preset) {
    case ScenePreset::Office:
      return "office";
    case ScenePreset::Cluttered:
      return "cluttered";
    case ScenePreset::Sparse:
      return "sparse";
  }
  return "office";
}

bool parsePreset(const std::string& name, ScenePreset* preset) {
  for (ScenePreset p : {ScenePreset::Office, ScenePreset::Cluttered, ScenePreset::Sparse})
    if (name == toString(p)) {
      *preset = p;
      return true;
    }
  return false;
}

ObjectMap Scene::groundTruthMap() const {
  ObjectMap map;
  for (const SimObject& o : objects) map.objects.push_back({o.id, o.category, o.label, o.ellipsoid()});
  map.points = points;
  return map;
}

Scene makeScene(ScenePreset preset, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Scene scene;
  const int n_objects = preset == ScenePreset::Office ? 20 : preset == ScenePreset::Cluttered ? 40 : 6;
  // Furniture: desks (0.75 m) and a shelf (1.1 m) around the room's middle.
  struct Surface {
    Eigen::Vector3d center;
    Eigen::Vector2d half;
    double yaw;
  };
  std::vector<Surface> surfaces;
  const int n_tables = preset == ScenePreset::Sparse ? 1 : 3;
  for (int t = 0; t < n_tables; ++t) {
    const double a = 2.0 * M_PI * t / n_tables + 0.4 * u(rng);
    const double r = 0.9 + 0.3 * u(rng);
    const double height = t == 2 ? 1.1 : 0.75;
    const double half_y = 0.35 + 0.1 * u(rng);  // drawn before x: see drawLastFirst
    const Eigen::Vector2d half(0.6 + 0.2 * u(rng), half_y);
    const double ty = a + M_PI / 2;
    surfaces.push_back({Eigen::Vector3d(r * std::cos(a), r * std::sin(a), height), half, ty});
    scene.furniture.push_back({PrimitiveShape::Box, Eigen::Vector3d(r * std::cos(a), r * std::sin(a), height - 0.02),
                               Eigen::Vector3d(half(0), half(1), 0.02), yaw(ty)});
    for (int k = 0; k < 4; ++k) {  // legs
      const Eigen::Vector3d leg((k & 1 ? 1 : -1) * (half(0) - 0.04), (k & 2 ? 1 : -1) * (half(1) - 0.04), 0);
      scene.furniture.push_back({PrimitiveShape::Box,
                                 Eigen::Vector3d(r * std::cos(a), r * std::sin(a), (height - 0.04) / 2) + yaw(ty) * leg,
                                 Eigen::Vector3d(0.025, 0.025, (height - 0.04) / 2), yaw(ty)});
    }
  }
  // Category mix: the cluttered preset repeats a few small categories many times.
  std::vector<int> pool;
  for (const Category& c : kCategories) pool.push_back(c.id);
  const std::vector<int> clutter = {41, 41, 41, 73, 73, 73, 39, 39};
  int id = 0;
  int attempts = 0;
  while (static_cast<int>(scene.objects.size()) < n_objects && attempts++ < 5000) {
    const int cat_id = preset == ScenePreset::Cluttered && u(rng) < 0.6
                           ? clutter[static_cast<size_t>(u(rng) * clutter.size()) % clutter.size()]
                           : pool[static_cast<size_t>(u(rng) * pool.size()) % pool.size()];
    const Category& cat = categoryById(cat_id);
    const bool on_floor = cat.kind == Kind::Chair || cat.kind == Kind::Teddy ||
                          (cat.kind == Kind::Box && u(rng) < 0.5) || surfaces.empty();
    double x, y, z, a;
    if (on_floor) {
      const double ang = 2 * M_PI * u(rng), r = 0.3 + 1.6 * u(rng);
      x = r * std::cos(ang), y = r * std::sin(ang), z = 0.0, a = 2 * M_PI * u(rng);
    } else {
      const Surface& s = surfaces[static_cast<size_t>(u(rng) * surfaces.size()) % surfaces.size()];
      const double local_y = (2 * u(rng) - 1) * (s.half(1) - 0.08);  // drawn before x: see drawLastFirst
      const Eigen::Vector3d local((2 * u(rng) - 1) * (s.half(0) - 0.1), local_y, 0);
      const Eigen::Vector3d w = s.center + yaw(s.yaw) * local;
      // TVs and laptops face the room's centre roughly; others any way.
      x = w(0), y = w(1), z = s.center(2);
      a = cat.kind == Kind::ThinBox && cat.id != 73 ? std::atan2(-y, -x) - M_PI / 2 + 0.6 * (u(rng) - 0.5)
                                                    : 2 * M_PI * u(rng);
    }
    SimObject o = makeObject(id, cat, x, y, z, a, rng);
    // No overlaps: keep the footprints' circles apart.
    bool clear = true;
    const double r_o = o.box_half.head<2>().norm();
    for (const SimObject& other : scene.objects) {
      const double d = (other.box_center.head<2>() - o.box_center.head<2>()).norm();
      const bool stacked = std::abs(other.box_center(2) - o.box_center(2)) > other.box_half(2) + o.box_half(2);
      if (!stacked && d < r_o + other.box_half.head<2>().norm() + 0.02) clear = false;
    }
    if (on_floor)
      for (const Surface& s : surfaces)
        if ((s.center.head<2>() - o.box_center.head<2>()).norm() < s.half.norm() + r_o) clear = false;
    if (!clear) continue;
    scene.objects.push_back(std::move(o));
    ++id;
  }
  // Map points: on objects and on furniture, as an ORB-SLAM map would hold them.
  for (const SimObject& o : scene.objects)
    for (int k = 0; k < 15; ++k)
      scene.points.push_back(surfacePoint(o.parts[static_cast<size_t>(k) % o.parts.size()], rng));
  for (const Primitive& f : scene.furniture)
    for (int k = 0; k < 10; ++k) scene.points.push_back(surfacePoint(f, rng));
  return scene;
}

std::vector<Pose> mappingTrajectory(const Scene& scene, int frames) {
  std::vector<Pose> poses;
  const double r = std::min(2.2, scene.room_half_size - 0.2);
  for (int i = 0; i < frames; ++i) {
    const double a = 2.0 * M_PI * i / std::max(1, frames);
    poses.push_back(Pose::lookAt(Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 1.4), Eigen::Vector3d(0, 0, 0.6)));
  }
  return poses;
}

std::vector<Pose> queryTrajectory(const Scene& scene, int frames, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Pose> poses;
  const double r_max = std::min(2.4, scene.room_half_size - 0.1);
  for (int i = 0; i < frames; ++i) {
    const double a = 2.0 * M_PI * u(rng);
    const double r = 1.5 + (r_max - 1.5) * u(rng);
    const double h = 0.8 + 1.2 * u(rng);
    const Eigen::Vector3d draws = detail::drawLastFirst<3>([&] { return u(rng); });
    const Eigen::Vector3d target(0.5 * (draws(0) - 0.5), 0.5 * (draws(1) - 0.5), 0.3 + 0.6 * draws(2));
    poses.push_back(Pose::lookAt(Eigen::Vector3d(r * std::cos(a), r * std::sin(a), h), target));
  }
  return poses;
}

}  // namespace ellreloc::sim
