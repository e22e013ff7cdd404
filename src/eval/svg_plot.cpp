#include "scfloam/eval/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace scfloam::svg {
namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

std::string stroke(const Style& s) {
  std::string a = "stroke=\"" + s.color + "\" stroke-width=\"" + num(s.width_px) + "\"";
  if (!s.dash.empty()) a += " stroke-dasharray=\"" + s.dash + "\"";
  if (s.opacity < 1.0) a += " stroke-opacity=\"" + num(s.opacity) + "\"";
  return a;
}

std::string tick_label(double v, double step) {
  if (std::abs(v) < step * 1e-9) v = 0;  // no "-0" or 1e-17 from accumulated steps
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int target) {
  if (!(hi > lo)) hi = lo + 1;
  const double raw = (hi - lo) / std::max(target, 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / mag;
  const double step = (norm < 1.5 ? 1 : norm < 3 ? 2 : norm < 7 ? 5 : 10) * mag;
  std::vector<double> ticks;
  for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + step * 1e-9; k += 1)
    ticks.push_back(k * step);
  return ticks;
}

std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

Canvas::Canvas(double width_px, double height_px) : width_(width_px), height_(height_px) {}

void Canvas::text(double x_px, double y_px, const std::string& text, double size_px,
                  const std::string& anchor, double rotate_deg, bool bold) {
  std::string e = "<text x=\"" + num(x_px) + "\" y=\"" + num(y_px) + "\" font-size=\"" +
                  num(size_px) + "\" text-anchor=\"" + anchor + "\"";
  if (bold) e += " font-weight=\"bold\"";
  if (rotate_deg != 0)
    e += " transform=\"rotate(" + num(rotate_deg) + " " + num(x_px) + " " + num(y_px) + ")\"";
  raw(e + ">" + escape(text) + "</text>");
}

std::string Canvas::str() const {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + num(width_) + "\" height=\"" +
         num(height_) + "\" viewBox=\"0 0 " + num(width_) + " " + num(height_) +
         "\" font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\">\n"
         "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n" + body_ + "</svg>\n";
}

Panel::Panel(Canvas& canvas, double left_px, double top_px, double width_px, double height_px)
    : canvas_(canvas), left_(left_px), top_(top_px), width_(width_px), height_(height_px) {}

void Panel::set_range(double x_min, double x_max, double y_min, double y_max, bool equal_aspect) {
  if (!(x_max > x_min)) { x_min -= 0.5; x_max += 0.5; }
  if (!(y_max > y_min)) { y_min -= 0.5; y_max += 0.5; }
  if (equal_aspect) {
    const double m_per_px = std::max((x_max - x_min) / width_, (y_max - y_min) / height_);
    const double cx = 0.5 * (x_min + x_max), cy = 0.5 * (y_min + y_max);
    x_min = cx - 0.5 * m_per_px * width_;
    x_max = cx + 0.5 * m_per_px * width_;
    y_min = cy - 0.5 * m_per_px * height_;
    y_max = cy + 0.5 * m_per_px * height_;
  }
  x_min_ = x_min; x_max_ = x_max; y_min_ = y_min; y_max_ = y_max;
}

double Panel::px(double x) const { return left_ + (x - x_min_) / (x_max_ - x_min_) * width_; }
double Panel::py(double y) const { return top_ + height_ - (y - y_min_) / (y_max_ - y_min_) * height_; }

void Panel::draw_axes(const std::string& title, const std::string& x_label,
                      const std::string& y_label) {
  const auto xt = nice_ticks(x_min_, x_max_, std::clamp(static_cast<int>(width_ / 90), 3, 9));
  const auto yt = nice_ticks(y_min_, y_max_, std::clamp(static_cast<int>(height_ / 38), 3, 9));
  const double x_step = xt.size() > 1 ? xt[1] - xt[0] : 1, y_step = yt.size() > 1 ? yt[1] - yt[0] : 1;
  const std::string grid = "stroke=\"#dddddd\" stroke-width=\"1\"";
  for (double x : xt) {
    canvas_.raw("<line x1=\"" + num(px(x)) + "\" y1=\"" + num(top_) + "\" x2=\"" + num(px(x)) +
                "\" y2=\"" + num(top_ + height_) + "\" " + grid + "/>");
    canvas_.text(px(x), top_ + height_ + 16, tick_label(x, x_step), 12);
  }
  for (double y : yt) {
    canvas_.raw("<line x1=\"" + num(left_) + "\" y1=\"" + num(py(y)) + "\" x2=\"" +
                num(left_ + width_) + "\" y2=\"" + num(py(y)) + "\" " + grid + "/>");
    canvas_.text(left_ - 6, py(y) + 4, tick_label(y, y_step), 12, "end");
  }
  canvas_.raw("<rect x=\"" + num(left_) + "\" y=\"" + num(top_) + "\" width=\"" + num(width_) +
              "\" height=\"" + num(height_) + "\" fill=\"none\" stroke=\"#333333\" stroke-width=\"1\"/>");
  canvas_.text(left_ + width_ / 2, top_ + height_ + 36, x_label, 13);
  canvas_.text(left_ - 56, top_ + height_ / 2, y_label, 13, "middle", -90);
  canvas_.text(left_ + width_ / 2, top_ - 10, title, 15, "middle", 0, true);
  // Everything drawn after this is clipped to the plotting area.
  clip_id_ = "clip" + std::to_string(static_cast<long>(left_)) + "_" + std::to_string(static_cast<long>(top_));
  canvas_.raw("<clipPath id=\"" + clip_id_ + "\"><rect x=\"" + num(left_) +
              "\" y=\"" + num(top_) + "\" width=\"" + num(width_) + "\" height=\"" + num(height_) +
              "\"/></clipPath>");
}

std::string Panel::clip() const {
  return clip_id_.empty() ? std::string() : " clip-path=\"url(#" + clip_id_ + ")\"";
}

void Panel::polyline(const std::vector<double>& x, const std::vector<double>& y, const Style& style) {
  std::string points;
  auto flush = [&] {
    if (!points.empty())
      canvas_.raw("<polyline fill=\"none\" stroke-linejoin=\"round\"" + clip() + " " + stroke(style) +
                  " points=\"" + points + "\"/>");
    points.clear();
  };
  const std::size_t n = std::min(x.size(), y.size());
  points.reserve(n * 16);
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) { flush(); continue; }  // gap, not a jump
    points += num(px(x[i])) + "," + num(py(y[i])) + " ";
    drawn_px_.emplace_back(px(x[i]), py(y[i]));
  }
  flush();
}

void Panel::markers(const std::vector<double>& x, const std::vector<double>& y, const Style& style,
                    double radius_px) {
  for (std::size_t i = 0; i < std::min(x.size(), y.size()); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
    drawn_px_.emplace_back(px(x[i]), py(y[i]));
    canvas_.raw("<circle cx=\"" + num(px(x[i])) + "\" cy=\"" + num(py(y[i])) + "\" r=\"" +
                num(radius_px) + "\" fill=\"" + style.color + "\"" + clip() + "/>");
  }
}

void Panel::segment(double x0, double y0, double x1, double y1, const Style& style) {
  for (double a = 0; a <= 1.0; a += 0.125)  // sample the line so the legend avoids it too
    drawn_px_.emplace_back(px(x0 + a * (x1 - x0)), py(y0 + a * (y1 - y0)));
  canvas_.raw("<line x1=\"" + num(px(x0)) + "\" y1=\"" + num(py(y0)) + "\" x2=\"" + num(px(x1)) +
              "\" y2=\"" + num(py(y1)) + "\" " + stroke(style) + clip() + "/>");
}

void Panel::center_text(const std::string& text) {
  canvas_.text(left_ + width_ / 2, top_ + height_ / 2, text, 14);
}

void Panel::legend(const std::vector<LegendEntry>& entries) {
  if (entries.empty()) return;
  std::size_t longest = 0;
  for (const auto& e : entries) longest = std::max(longest, e.label.size());
  const double row = 18, box_w = 44 + 7.0 * static_cast<double>(longest), box_h = row * entries.size() + 8;
  double x = left_ + 10, y = top_ + 10;
  std::size_t fewest = std::numeric_limits<std::size_t>::max();
  for (int corner = 0; corner < 4; ++corner) {  // top-left, top-right, bottom-left, bottom-right
    const double cx = corner % 2 == 0 ? left_ + 10 : left_ + width_ - 10 - box_w;
    const double cy = corner < 2 ? top_ + 10 : top_ + height_ - 10 - box_h;
    std::size_t covered = 0;
    for (const auto& [px_x, px_y] : drawn_px_)
      if (px_x >= cx - 4 && px_x <= cx + box_w + 4 && px_y >= cy - 4 && px_y <= cy + box_h + 4) ++covered;
    if (covered < fewest) {
      fewest = covered;
      x = cx;
      y = cy;
    }
  }
  canvas_.raw("<rect x=\"" + num(x) + "\" y=\"" + num(y) + "\" width=\"" + num(box_w) +
              "\" height=\"" + num(box_h) + "\" fill=\"white\" fill-opacity=\"0.85\" stroke=\"#999999\"/>");
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const double cy = y + 4 + row * (static_cast<double>(i) + 0.5);
    const auto& e = entries[i];
    if (e.marker)
      canvas_.raw("<circle cx=\"" + num(x + 17) + "\" cy=\"" + num(cy) + "\" r=\"4\" fill=\"" +
                  e.style.color + "\"/>");
    else
      canvas_.raw("<line x1=\"" + num(x + 6) + "\" y1=\"" + num(cy) + "\" x2=\"" + num(x + 28) +
                  "\" y2=\"" + num(cy) + "\" " + stroke(e.style) + "/>");
    canvas_.text(x + 36, cy + 4, e.label, 12, "start");
  }
}

}  // namespace scfloam::svg

