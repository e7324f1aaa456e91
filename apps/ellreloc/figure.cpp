#include "figure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "ellreloc/error.hpp"
#include "ellreloc/io/image_codec.hpp"

namespace ellreloc::cli {

void Figure::line(Point2 a, Point2 b, Rgb colour, double width, bool dashed) {
  items_.push_back(Line{{a, b}, colour, width, dashed});
}
void Figure::polyline(std::vector<Point2> points, Rgb colour, double width) {
  items_.push_back(Line{std::move(points), colour, width, false});
}
void Figure::polygon(std::vector<Point2> points, Rgb stroke, Rgb fill, double fill_opacity) {
  items_.push_back(Polygon{std::move(points), stroke, fill, fill_opacity});
}
void Figure::circle(Point2 centre, double radius, Rgb fill) { items_.push_back(Circle{centre, radius, fill}); }
void Figure::rectangle(Point2 a, Point2 b, Rgb stroke, std::optional<Rgb> fill) {
  items_.push_back(Rectangle{a, b, stroke, fill});
}
void Figure::text(Point2 at, std::string text, double size, Anchor anchor, Rgb colour, bool vertical) {
  items_.push_back(Text{at, std::move(text), size, anchor, colour, vertical});
}

// --- SVG ------------------------------------------------------------------------------------

std::string escapeXml(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

namespace {

std::string rgb(Rgb c) {
  char s[32];
  std::snprintf(s, sizeof s, "rgb(%d,%d,%d)", c.r, c.g, c.b);
  return s;
}

std::string num(double v) {
  char s[32];
  std::snprintf(s, sizeof s, "%.2f", v);
  return s;
}

std::string pointsAttribute(const std::vector<Point2>& points) {
  std::string s;
  for (const Point2& p : points) s += num(p.x) + "," + num(p.y) + " ";
  return s;
}

}  // namespace

std::string Figure::svg() const {
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width_ << "\" height=\"" << height_
    << "\" viewBox=\"0 0 " << width_ << " " << height_ << "\" font-family=\"DejaVu Sans, Arial, sans-serif\">\n";
  s << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  for (const Item& item : items_) {
    if (const auto* l = std::get_if<Line>(&item)) {
      s << "<polyline fill=\"none\" stroke=\"" << rgb(l->colour) << "\" stroke-width=\"" << num(l->width) << "\""
        << (l->dashed ? " stroke-dasharray=\"6,4\"" : "") << " points=\"" << pointsAttribute(l->points) << "\"/>\n";
    } else if (const auto* p = std::get_if<Polygon>(&item)) {
      s << "<polygon fill=\"" << rgb(p->fill) << "\" fill-opacity=\"" << num(p->fill_opacity) << "\" stroke=\""
        << rgb(p->stroke) << "\" stroke-width=\"1\" points=\"" << pointsAttribute(p->points) << "\"/>\n";
    } else if (const auto* c = std::get_if<Circle>(&item)) {
      s << "<circle cx=\"" << num(c->centre.x) << "\" cy=\"" << num(c->centre.y) << "\" r=\"" << num(c->radius)
        << "\" fill=\"" << rgb(c->fill) << "\"/>\n";
    } else if (const auto* r = std::get_if<Rectangle>(&item)) {
      s << "<rect x=\"" << num(std::min(r->a.x, r->b.x)) << "\" y=\"" << num(std::min(r->a.y, r->b.y)) << "\" width=\""
        << num(std::abs(r->b.x - r->a.x)) << "\" height=\"" << num(std::abs(r->b.y - r->a.y)) << "\" fill=\""
        << (r->fill ? rgb(*r->fill) : std::string("none")) << "\" stroke=\"" << rgb(r->stroke) << "\"/>\n";
    } else if (const auto* t = std::get_if<Text>(&item)) {
      const char* anchor = t->anchor == Anchor::Start ? "start" : t->anchor == Anchor::Middle ? "middle" : "end";
      s << "<text x=\"" << num(t->at.x) << "\" y=\"" << num(t->at.y) << "\" font-size=\"" << num(t->size)
        << "\" text-anchor=\"" << anchor << "\" fill=\"" << rgb(t->colour) << "\"";
      if (t->vertical) s << " transform=\"rotate(-90 " << num(t->at.x) << " " << num(t->at.y) << ")\"";
      s << ">" << escapeXml(t->text) << "</text>\n";
    }
  }
  s << "</svg>\n";
  return s.str();
}

// --- PNG ------------------------------------------------------------------------------------

namespace {

constexpr int kShift = 3;  // OpenCV's fractional bits: coordinates to 1/8 pixel

cv::Point fixed(Point2 p) {
  return {static_cast<int>(std::lround(p.x * (1 << kShift))), static_cast<int>(std::lround(p.y * (1 << kShift)))};
}
cv::Scalar bgr(Rgb c) { return cv::Scalar(c.b, c.g, c.r); }
int thickness(double width) { return std::max(1, static_cast<int>(std::lround(width))); }

void dashedLine(cv::Mat& img, Point2 a, Point2 b, const cv::Scalar& colour, int width) {
  const double length = std::hypot(b.x - a.x, b.y - a.y);
  for (double s = 0; s < length; s += 10.0) {
    const double e = std::min(length, s + 6.0);
    const Point2 p{a.x + (b.x - a.x) * s / length, a.y + (b.y - a.y) * s / length};
    const Point2 q{a.x + (b.x - a.x) * e / length, a.y + (b.y - a.y) * e / length};
    cv::line(img, fixed(p), fixed(q), colour, width, cv::LINE_AA, kShift);
  }
}

// Hershey fonts are about 22 px tall at scale 1; a font of `size` px maps to size / 30 so that
// capital letters come out about as tall as in the SVG.
void drawText(cv::Mat& img, const std::string& text, Point2 at, double size, Anchor anchor, Rgb colour, bool vertical) {
  const double scale = size / 30.0;
  int baseline = 0;
  const cv::Size extent = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline);
  const double shift = anchor == Anchor::Start ? 0.0 : anchor == Anchor::Middle ? extent.width / 2.0 : extent.width;
  if (!vertical) {
    cv::putText(img, text, cv::Point(static_cast<int>(at.x - shift), static_cast<int>(at.y)), cv::FONT_HERSHEY_SIMPLEX,
                scale, bgr(colour), 1, cv::LINE_AA);
    return;
  }
  // Drawn horizontally on a patch, turned a quarter to the left, and laid where it is darker.
  cv::Mat patch(extent.height + baseline + 2, extent.width + 2, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(patch, text, cv::Point(1, extent.height + 1), cv::FONT_HERSHEY_SIMPLEX, scale, bgr(colour), 1,
              cv::LINE_AA);
  cv::rotate(patch, patch, cv::ROTATE_90_COUNTERCLOCKWISE);
  const int x0 = static_cast<int>(at.x) - patch.cols + baseline, y0 = static_cast<int>(at.y - patch.rows + shift);
  for (int y = 0; y < patch.rows; ++y)
    for (int x = 0; x < patch.cols; ++x) {
      const int X = x0 + x, Y = y0 + y;
      if (X < 0 || Y < 0 || X >= img.cols || Y >= img.rows) continue;
      const cv::Vec3b p = patch.at<cv::Vec3b>(y, x);
      cv::Vec3b& q = img.at<cv::Vec3b>(Y, X);
      if (p[0] + p[1] + p[2] < q[0] + q[1] + q[2]) q = p;
    }
}

}  // namespace

std::string Figure::png() const {
  cv::Mat img(height_, width_, CV_8UC3, cv::Scalar(255, 255, 255));
  for (const Item& item : items_) {
    if (const auto* l = std::get_if<Line>(&item)) {
      for (size_t i = 1; i < l->points.size(); ++i) {
        if (l->dashed)
          dashedLine(img, l->points[i - 1], l->points[i], bgr(l->colour), thickness(l->width));
        else
          cv::line(img, fixed(l->points[i - 1]), fixed(l->points[i]), bgr(l->colour), thickness(l->width), cv::LINE_AA,
                   kShift);
      }
    } else if (const auto* p = std::get_if<Polygon>(&item)) {
      std::vector<cv::Point> points;
      for (const Point2& q : p->points) points.push_back(fixed(q));
      cv::Mat filled = img.clone();
      cv::fillPoly(filled, std::vector<std::vector<cv::Point>>{points}, bgr(p->fill), cv::LINE_AA, kShift);
      cv::addWeighted(filled, p->fill_opacity, img, 1.0 - p->fill_opacity, 0.0, img);
      cv::polylines(img, std::vector<std::vector<cv::Point>>{points}, true, bgr(p->stroke), 1, cv::LINE_AA, kShift);
    } else if (const auto* c = std::get_if<Circle>(&item)) {
      cv::circle(img, fixed(c->centre), static_cast<int>(std::lround(c->radius * (1 << kShift))), bgr(c->fill),
                 cv::FILLED, cv::LINE_AA, kShift);
    } else if (const auto* r = std::get_if<Rectangle>(&item)) {
      if (r->fill) cv::rectangle(img, fixed(r->a), fixed(r->b), bgr(*r->fill), cv::FILLED, cv::LINE_AA, kShift);
      cv::rectangle(img, fixed(r->a), fixed(r->b), bgr(r->stroke), 1, cv::LINE_AA, kShift);
    } else if (const auto* t = std::get_if<Text>(&item)) {
      drawText(img, t->text, t->at, t->size, t->anchor, t->colour, t->vertical);
    }
  }
  return io::encodePng(img.data, img.cols, img.rows, io::PixelFormat::Bgr8, img.step, 9);
}

// --- Axes -------------------------------------------------------------------------------------

double tickStep(double range, int ticks) {
  if (!(range > 0) || !std::isfinite(range)) return 1.0;
  const double raw = range / ticks;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * power >= raw) return m * power;
  return 10.0 * power;
}

Axes::Axes(Figure& figure, double left, double top, double width, double height)
    : figure_(figure), left_(left), top_(top), width_(width), height_(height) {}

void Axes::setLimits(double x0, double x1, double y0, double y1, bool equal_aspect) {
  if (!(x1 > x0)) x1 = x0 + 1.0;
  if (!(y1 > y0)) y1 = y0 + 1.0;
  if (equal_aspect) {  // widen the narrower range around its middle
    const double per_px = std::max((x1 - x0) / width_, (y1 - y0) / height_);
    const double xm = 0.5 * (x0 + x1), ym = 0.5 * (y0 + y1);
    x0 = xm - 0.5 * per_px * width_, x1 = xm + 0.5 * per_px * width_;
    y0 = ym - 0.5 * per_px * height_, y1 = ym + 0.5 * per_px * height_;
  }
  x0_ = x0, x1_ = x1, y0_ = y0, y1_ = y1;
}

Point2 Axes::at(double x, double y) const {
  return {left_ + (x - x0_) / (x1_ - x0_) * width_, top_ + height_ - (y - y0_) / (y1_ - y0_) * height_};
}

void Axes::draw(const std::string& title, const std::string& x_label, const std::string& y_label) {
  const Rgb grid{225, 225, 225}, ink{40, 40, 40};
  const auto label = [](double v, double step) {
    char s[32];
    std::snprintf(s, sizeof s, "%.*f", step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step))), v);
    return std::string(s);
  };
  const double xs = tickStep(x1_ - x0_), ys = tickStep(y1_ - y0_);
  for (double x = std::ceil(x0_ / xs) * xs; x <= x1_ + 1e-9 * xs; x += xs) {
    figure_.line(at(x, y0_), at(x, y1_), grid);
    figure_.line(at(x, y0_), {at(x, y0_).x, at(x, y0_).y + 5}, ink);
    figure_.text({at(x, y0_).x, at(x, y0_).y + 18}, label(std::abs(x) < 1e-12 ? 0.0 : x, xs), 11, Anchor::Middle, ink);
  }
  for (double y = std::ceil(y0_ / ys) * ys; y <= y1_ + 1e-9 * ys; y += ys) {
    figure_.line(at(x0_, y), at(x1_, y), grid);
    figure_.line({at(x0_, y).x - 5, at(x0_, y).y}, at(x0_, y), ink);
    figure_.text({at(x0_, y).x - 8, at(x0_, y).y + 4}, label(std::abs(y) < 1e-12 ? 0.0 : y, ys), 11, Anchor::End, ink);
  }
  figure_.rectangle({left_, top_}, {left_ + width_, top_ + height_}, ink);
  figure_.text({left_ + width_ / 2, top_ - 10}, title, 14, Anchor::Middle, ink);
  figure_.text({left_ + width_ / 2, top_ + height_ + 38}, x_label, 12, Anchor::Middle, ink);
  figure_.text({left_ - 42, top_ + height_ / 2}, y_label, 12, Anchor::Middle, ink, true);
}

}  // namespace ellreloc::cli
