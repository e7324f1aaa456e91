#pragma once
// A small vector figure for the command line's plots: shapes and text in pixel coordinates
// (y down), written as SVG (text stays text) or as PNG (drawn with OpenCV). Axes map data
// coordinates into a rectangle of the figure and draw ticks, grid, labels.

#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace ellreloc::cli {

struct Rgb {
  int r = 0, g = 0, b = 0;
};

struct Point2 {
  double x = 0, y = 0;
};

enum class Anchor { Start, Middle, End };

class Figure {
 public:
  Figure(int width, int height) : width_(width), height_(height) {}

  void line(Point2 a, Point2 b, Rgb colour, double width = 1.0, bool dashed = false);
  void polyline(std::vector<Point2> points, Rgb colour, double width = 1.5);
  void polygon(std::vector<Point2> points, Rgb stroke, Rgb fill, double fill_opacity);
  void circle(Point2 centre, double radius, Rgb fill);
  void rectangle(Point2 a, Point2 b, Rgb stroke, std::optional<Rgb> fill = std::nullopt);
  /// `size` is the font's height in pixels; `vertical` text reads bottom to top.
  void text(Point2 at, std::string text, double size = 12, Anchor anchor = Anchor::Start, Rgb colour = {},
            bool vertical = false);

  int width() const { return width_; }
  int height() const { return height_; }
  std::string svg() const;
  std::string png() const;  ///< the encoded PNG file

 private:
  struct Line {
    std::vector<Point2> points;
    Rgb colour;
    double width;
    bool dashed;
  };
  struct Polygon {
    std::vector<Point2> points;
    Rgb stroke, fill;
    double fill_opacity;
  };
  struct Circle {
    Point2 centre;
    double radius;
    Rgb fill;
  };
  struct Rectangle {
    Point2 a, b;
    Rgb stroke;
    std::optional<Rgb> fill;
  };
  struct Text {
    Point2 at;
    std::string text;
    double size;
    Anchor anchor;
    Rgb colour;
    bool vertical;
  };
  using Item = std::variant<Line, Polygon, Circle, Rectangle, Text>;
  int width_, height_;
  std::vector<Item> items_;
};

/// Data coordinates in a rectangle of a figure.
class Axes {
 public:
  /// The plot area: left, top, width, height in figure pixels.
  Axes(Figure& figure, double left, double top, double width, double height);
  /// Data ranges; with `equal_aspect` one unit is as long on both axes (the ranges grow to fit).
  void setLimits(double x0, double x1, double y0, double y1, bool equal_aspect = false);
  Point2 at(double x, double y) const;
  /// The frame, ticks at round steps with their values, a light grid, the title and axis labels.
  void draw(const std::string& title, const std::string& x_label, const std::string& y_label);
  Figure& figure() { return figure_; }
  double right() const { return left_ + width_; }
  double top() const { return top_; }

 private:
  Figure& figure_;
  double left_, top_, width_, height_;
  double x0_ = 0, x1_ = 1, y0_ = 0, y1_ = 1;
};

/// Text with &, <, > and " escaped, for SVG and HTML.
std::string escapeXml(const std::string& text);

/// A round tick step (1, 2 or 5 times a power of ten) giving about `ticks` ticks over `range`.
double tickStep(double range, int ticks = 6);

}  // namespace ellreloc::cli
