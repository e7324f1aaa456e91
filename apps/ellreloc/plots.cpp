// The comparison figure of `ellreloc evaluate --plot` and `ellreloc report`: cumulative
// position and rotation error curves of every method (the paper's Figs. 6-7, with the 30 cm /
// 30 degree validity thresholds), and a top view in metres with the map's objects, the true
// camera positions and each estimate joined to its true position.

#include <algorithm>
#include <cmath>

#include "commands.hpp"
#include "figure.hpp"

namespace ellreloc::cli {

namespace {

const Rgb kMethodColours[] = {{31, 119, 180}, {255, 127, 14},  {44, 160, 44},
                              {214, 39, 40},  {148, 103, 189}, {140, 86, 75}};
const Rgb kCategoryColours[] = {{166, 206, 227}, {178, 223, 138}, {251, 154, 153}, {253, 191, 111}, {202, 178, 214},
                                {255, 255, 153}, {177, 89, 40},   {31, 120, 180},  {51, 160, 44},   {227, 26, 28}};
const Rgb kInk{40, 40, 40}, kTruth{120, 120, 120};

Rgb methodColour(size_t i) { return kMethodColours[i % std::size(kMethodColours)]; }

/// Share of query frames (%) with an error at most x, as a step curve from 0 to `x_max`.
std::vector<Point2> cumulativeCurve(const Axes& axes, std::vector<double> errors, size_t frames, double x_max) {
  std::sort(errors.begin(), errors.end());
  std::vector<Point2> points = {axes.at(0, 0)};
  double share = 0;
  for (double e : errors) {
    if (e > x_max) break;
    points.push_back(axes.at(e, share));
    share += 100.0 / static_cast<double>(frames);
    points.push_back(axes.at(e, share));
  }
  points.push_back(axes.at(x_max, share));
  return points;
}

void cumulativePanel(Axes axes, const Evaluation& e, bool rotation) {
  const double x_max = 2 * (rotation ? kValidRotationDeg : kValidPositionCm);
  axes.setLimits(0, x_max, 0, 100);
  axes.draw(rotation ? "Rotation error" : "Position error", rotation ? "rotation error (deg)" : "position error (cm)",
            "query frames within the error (%)");
  const double threshold = rotation ? kValidRotationDeg : kValidPositionCm;
  axes.figure().line(axes.at(threshold, 0), axes.at(threshold, 100), kInk, 1.0, true);
  axes.figure().text({axes.at(threshold, 4).x + 4, axes.at(threshold, 4).y},
                     rotation ? "valid: < 30 deg" : "valid: < 30 cm", 11, Anchor::Start, kInk);
  for (size_t m = 0; m < e.methods.size(); ++m) {
    std::vector<double> errors;
    for (const std::optional<PoseError>& err : e.methods[m].errors)
      if (err) errors.push_back(rotation ? err->rotation_deg : err->position_cm);
    axes.figure().polyline(cumulativeCurve(axes, errors, e.frames.size(), x_max), methodColour(m), 2.0);
  }
}

/// Top view: the two world axes along which the true camera centres spread most (the third is
/// taken as up).
void topViewPanel(Axes axes, const Evaluation& e, const ObjectMap* map) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero(), var = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& c : e.truth) mean += c / static_cast<double>(e.truth.size());
  for (const Eigen::Vector3d& c : e.truth) var += (c - mean).cwiseAbs2();
  int up = 0;
  var.minCoeff(&up);
  const int u = up == 0 ? 1 : 0, v = up == 2 ? 1 : 2;
  Eigen::AlignedBox2d box;
  for (const Eigen::Vector3d& c : e.truth) box.extend(Eigen::Vector2d(c(u), c(v)));
  if (map)
    for (const MapObject& o : map->objects)
      box.extend(Eigen::Vector2d(o.ellipsoid.center()(u), o.ellipsoid.center()(v)));
  const Eigen::Vector2d margin = Eigen::Vector2d::Constant(0.1 * box.sizes().maxCoeff() + 0.2);
  box.extend(box.min() - margin).extend(box.max() + margin);
  axes.setLimits(box.min().x(), box.max().x(), box.min().y(), box.max().y(), true);
  const char* names[3] = {"x", "y", "z"};
  axes.draw("Top view", std::string(names[u]) + " (m)", std::string(names[v]) + " (m)");
  const auto inside = [&](const Eigen::Vector3d& c) { return box.contains(Eigen::Vector2d(c(u), c(v))); };
  if (map) {
    for (const MapObject& o : map->objects) {
      // The ellipsoid's footprint: the ellipse of its shape matrix's (u, v) block.
      const Eigen::Matrix3d S = o.ellipsoid.shapeMatrix();
      Eigen::Matrix2d block;
      block << S(u, u), S(u, v), S(v, u), S(v, v);
      const Eigen::Vector2d centre(o.ellipsoid.center()(u), o.ellipsoid.center()(v));
      const auto footprint = Ellipse::fromGaussian(centre, block);
      if (!footprint || !inside(o.ellipsoid.center())) continue;
      std::vector<Point2> outline;
      for (const Eigen::Vector2d& p : footprint->sampleBoundary(48)) outline.push_back(axes.at(p.x(), p.y()));
      const Rgb colour = kCategoryColours[static_cast<size_t>(std::abs(o.category)) % std::size(kCategoryColours)];
      axes.figure().polygon(outline, {110, 110, 110}, colour, 0.6);
    }
  }
  for (const Eigen::Vector3d& c : e.truth) axes.figure().circle(axes.at(c(u), c(v)), 2.5, kTruth);
  int outside = 0;
  for (size_t m = 0; m < e.methods.size(); ++m)
    for (size_t i = 0; i < e.frames.size(); ++i) {
      const std::optional<Eigen::Vector3d>& c = e.methods[m].centres[i];
      if (!c) continue;
      if (!inside(*c)) {
        ++outside;
        continue;
      }
      axes.figure().line(axes.at(e.truth[i](u), e.truth[i](v)), axes.at((*c)(u), (*c)(v)), methodColour(m), 1.0);
      axes.figure().circle(axes.at((*c)(u), (*c)(v)), 2.5, methodColour(m));
    }
  if (outside > 0)
    axes.figure().text({axes.right() - 6, axes.top() + 16}, std::to_string(outside) + " estimates beyond the view", 11,
                       Anchor::End, kInk);
}

}  // namespace

Figure comparisonFigure(const Evaluation& e, const ObjectMap* map) {
  Figure figure(1500, 540);
  cumulativePanel(Axes(figure, 80, 50, 380, 380), e, false);
  cumulativePanel(Axes(figure, 580, 50, 380, 380), e, true);
  topViewPanel(Axes(figure, 1080, 50, 380, 380), e, map);
  // Legend: one entry per method, then the top view's marks.
  double x = 80;
  const double y = 515;
  for (size_t m = 0; m < e.methods.size(); ++m) {
    figure.line({x, y - 4}, {x + 24, y - 4}, methodColour(m), 2.0);
    char text[160];
    const RelocalizationSummary& s = e.methods[m].summary;
    std::snprintf(text, sizeof text, "%s (%.1f%% valid)", e.methods[m].label.c_str(), s.validPercent());
    figure.text({x + 30, y}, text, 12, Anchor::Start, kInk);
    x += 40 + 7.5 * static_cast<double>(std::string(text).size());
  }
  figure.circle({x + 8, y - 4}, 3, kTruth);
  figure.text({x + 16, y}, "true position (top view; estimates joined to it)", 12, Anchor::Start, kInk);
  x += 330;
  if (map) {
    figure.polygon({{x, y - 10}, {x + 18, y - 10}, {x + 18, y + 2}, {x, y + 2}}, {110, 110, 110}, kCategoryColours[0],
                   0.6);
    figure.text({x + 24, y}, "map objects, coloured by category", 12, Anchor::Start, kInk);
  }
  return figure;
}

}  // namespace ellreloc::cli
