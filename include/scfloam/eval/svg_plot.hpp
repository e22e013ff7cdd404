// A small SVG chart writer: panels with labelled axes, "nice" ticks, grid, polylines, markers,
// segments and a legend. Enough for the evaluation plots without a runtime dependency.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace scfloam::svg {

// About `target` round tick values (1, 2, 5 x 10^k steps) covering [lo, hi].
std::vector<double> nice_ticks(double lo, double hi, int target = 6);

// Escapes &, <, >, " for SVG text and attributes.
std::string escape(const std::string& text);

struct Style {
  std::string color = "#1f77b4";
  double width_px = 1.5;
  std::string dash;       // SVG stroke-dasharray, "" for solid
  double opacity = 1.0;
};

class Canvas;

// A rectangular plot area mapping data coordinates to pixels.
class Panel {
 public:
  // Box in pixels (left, top, width, height) of the plotting area proper (axes labels outside).
  Panel(Canvas& canvas, double left_px, double top_px, double width_px, double height_px);

  // Data range; with equal_aspect the smaller span is widened so 1 m is as long on both axes.
  void set_range(double x_min, double x_max, double y_min, double y_max, bool equal_aspect = false);
  // Frame, grid, ticks, axis labels and title.
  void draw_axes(const std::string& title, const std::string& x_label, const std::string& y_label);

  void polyline(const std::vector<double>& x, const std::vector<double>& y, const Style& style);
  void markers(const std::vector<double>& x, const std::vector<double>& y, const Style& style,
               double radius_px);
  void segment(double x0, double y0, double x1, double y1, const Style& style);
  // A note written in the middle of the panel (e.g. "no data").
  void center_text(const std::string& text);

  struct LegendEntry {
    std::string label;
    Style style;
    bool marker = false;
  };
  // Drawn in the inside corner that covers the fewest of the points drawn so far.
  void legend(const std::vector<LegendEntry>& entries);

  double px(double x) const;
  double py(double y) const;

 private:
  std::string clip() const;  // clip-path attribute once the axes exist

  Canvas& canvas_;
  std::string clip_id_;
  std::vector<std::pair<double, double>> drawn_px_;  // for placing the legend
  double left_, top_, width_, height_;
  double x_min_ = 0, x_max_ = 1, y_min_ = 0, y_max_ = 1;
};

class Canvas {
 public:
  Canvas(double width_px, double height_px);
  void raw(const std::string& element) { body_ += element; body_ += '\n'; }
  void text(double x_px, double y_px, const std::string& text, double size_px,
            const std::string& anchor = "middle", double rotate_deg = 0, bool bold = false);
  std::string str() const;  // the complete SVG document

 private:
  double width_, height_;
  std::string body_;
};

}  // namespace scfloam::svg
