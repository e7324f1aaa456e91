// Uses both the header-only core and the compiled library from an installed package, through
// the umbrella header (so every installed header must compile).
#include <ellreloc/ellreloc.hpp>

#include <cstdio>
#include <filesystem>

int main() {
  using namespace ellreloc;
  ObjectMap map;
  map.objects.push_back({1, 41, "cup", Ellipsoid({0, 0, 2}, {0.04, 0.04, 0.06}, Eigen::Matrix3d::Identity())});
  const std::string path = (std::filesystem::temp_directory_path() / "ellreloc_consumer_map.json").string();
  io::writeMap(path, map);
  const ObjectMap back = io::readMap(path);
  std::filesystem::remove(path);
  const Projection p = project(back.objects.at(0).ellipsoid, Intrinsics(500, 500, 320, 240, 640, 480), Pose());
  if (!p || std::abs(p.ellipse.center()(0) - 320.0) > 1e-9) return 1;
  std::printf("consumer ok: cup at (%.1f, %.1f)\n", p.ellipse.center()(0), p.ellipse.center()(1));
  return 0;
}
