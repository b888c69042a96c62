#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <stb_easy_font.h>

#include <shapedb/io/plot.h>

namespace shapedb::io {

namespace {

using Color = std::array<std::uint8_t, 3>;
constexpr Color kBlack{0, 0, 0};
constexpr Color kGrid{225, 225, 225};
constexpr Color kText{40, 40, 40};
constexpr int kTextScale = 2;  ///< stb_easy_font's glyphs are 7 pixels tall: drawn at twice that

class Canvas {
 public:
  Canvas(int width, int height) {
    mImage.width = width;
    mImage.height = height;
    mImage.rgb.assign(static_cast<std::size_t>(width) * height * 3, 255);
  }
  Image take() { return std::move(mImage); }

  void pixel(int x, int y, const Color& c) {
    if (x < 0 || y < 0 || x >= mImage.width || y >= mImage.height) return;
    std::uint8_t* p = &mImage.rgb[(static_cast<std::size_t>(y) * mImage.width + x) * 3];
    p[0] = c[0];
    p[1] = c[1];
    p[2] = c[2];
  }
  void rect(double x0, double y0, double x1, double y1, const Color& c) {
    for (int y = static_cast<int>(std::floor(y0)); y < static_cast<int>(std::ceil(y1)); ++y)
      for (int x = static_cast<int>(std::floor(x0)); x < static_cast<int>(std::ceil(x1)); ++x)
        pixel(x, y, c);
  }
  void line(double x0, double y0, double x1, double y1, const Color& c, int thickness = 1) {
    const int steps = static_cast<int>(std::ceil(std::max(std::abs(x1 - x0), std::abs(y1 - y0)))) + 1;
    for (int i = 0; i <= steps; ++i) {
      const double t = static_cast<double>(i) / steps;
      const double x = x0 + t * (x1 - x0), y = y0 + t * (y1 - y0);
      rect(x - thickness / 2.0, y - thickness / 2.0, x + thickness / 2.0, y + thickness / 2.0, c);
    }
  }
  void dot(double x, double y, double radius, const Color& c) {
    for (int dy = -static_cast<int>(radius); dy <= static_cast<int>(radius); ++dy)
      for (int dx = -static_cast<int>(radius); dx <= static_cast<int>(radius); ++dx)
        if (dx * dx + dy * dy <= radius * radius)
          pixel(static_cast<int>(std::lround(x)) + dx, static_cast<int>(std::lround(y)) + dy, c);
  }
  static int textWidth(const std::string& text) {
    return kTextScale * stb_easy_font_width(const_cast<char*>(text.c_str()));
  }
  /// Text with its top-left corner at (x, y).
  void text(double x, double y, const std::string& text, const Color& c) {
    struct Vertex {
      float x, y, z;
      unsigned char color[4];
    };
    std::vector<Vertex> quads(text.size() * 70 + 4);
    const int n = stb_easy_font_print(0.0f, 0.0f, const_cast<char*>(text.c_str()), nullptr, quads.data(),
                                      static_cast<int>(quads.size() * sizeof(Vertex)));
    for (int q = 0; q < n; ++q) {
      const Vertex* v = &quads[static_cast<std::size_t>(q) * 4];
      const float qx0 = std::min({v[0].x, v[1].x, v[2].x, v[3].x});
      const float qx1 = std::max({v[0].x, v[1].x, v[2].x, v[3].x});
      const float qy0 = std::min({v[0].y, v[1].y, v[2].y, v[3].y});
      const float qy1 = std::max({v[0].y, v[1].y, v[2].y, v[3].y});
      rect(x + kTextScale * qx0, y + kTextScale * qy0, x + kTextScale * qx1, y + kTextScale * qy1, c);
    }
  }

 private:
  Image mImage;
};

/// One axis: the data range mapped to pixels, linear or by log10.
struct Axis {
  bool log = false;
  double lo = 0.0, hi = 1.0;  ///< in axis units (log10 of the value on a log axis)
  double toUnits(double v) const { return log ? std::log10(v) : v; }
  bool accepts(double v) const { return std::isfinite(v) && (!log || v > 0.0); }
  double fraction(double v) const { return (toUnits(v) - lo) / (hi - lo); }
};

Axis fitAxis(bool log, const std::vector<double>& values, bool categories, std::size_t categoryCount) {
  Axis axis;
  axis.log = log && !categories;
  if (categories) {
    axis.lo = -0.5;
    axis.hi = static_cast<double>(categoryCount) - 0.5;
    return axis;
  }
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : values)
    if (axis.accepts(v)) {
      lo = std::min(lo, axis.toUnits(v));
      hi = std::max(hi, axis.toUnits(v));
    }
  if (!(lo <= hi)) {
    lo = 0.0;
    hi = 1.0;
  }
  if (axis.log) {
    lo = std::floor(lo);
    hi = std::max(std::ceil(hi), lo + 1.0);
  } else {
    const double pad = hi > lo ? 0.05 * (hi - lo) : std::max(1.0, std::abs(hi)) * 0.5;
    lo -= pad;
    hi += pad;
    if (lo > 0.0 && lo < 0.3 * hi) lo = 0.0;  // errors and times start at zero when it is near
  }
  axis.lo = lo;
  axis.hi = hi;
  return axis;
}

/// Tick positions (in axis units): decades on a log axis, 1-2-5 steps on a linear one.
std::vector<double> ticks(const Axis& axis) {
  std::vector<double> out;
  if (axis.log) {
    const int step = std::max(1, static_cast<int>(std::ceil((axis.hi - axis.lo) / 8.0)));
    for (double d = std::ceil(axis.lo); d <= axis.hi + 1e-9; d += step)
      out.push_back(d);
    return out;
  }
  const double raw = (axis.hi - axis.lo) / 6.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = magnitude;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * magnitude >= raw) {
      step = m * magnitude;
      break;
    }
  for (double t = std::ceil(axis.lo / step) * step; t <= axis.hi + 1e-9 * step; t += step)
    out.push_back(std::abs(t) < 1e-12 * step ? 0.0 : t);
  return out;
}

std::string tickLabel(const Axis& axis, double units) {
  char buffer[32];
  if (axis.log)
    std::snprintf(buffer, sizeof buffer, "%g", std::pow(10.0, units));
  else
    std::snprintf(buffer, sizeof buffer, "%g", units);
  return buffer;
}

}  // namespace

Image plotChart(const PlotAxes& axes, std::span<const PlotSeries> series, int width, int height) {
  Canvas canvas(width, height);
  const bool categorical = !axes.categories.empty();
  std::vector<double> xs, ys;
  for (const PlotSeries& s : series) {
    xs.insert(xs.end(), s.x.begin(), s.x.end());
    ys.insert(ys.end(), s.y.begin(), s.y.end());
  }
  const Axis xAxis = fitAxis(axes.logX, xs, categorical, axes.categories.size());
  const Axis yAxis = fitAxis(axes.logY, ys, false, 0);

  const double left = 90, right = width - 40.0, top = 60, bottom = height - 70.0;
  auto px = [&](double x) { return left + xAxis.fraction(x) * (right - left); };
  auto py = [&](double y) { return bottom - yAxis.fraction(y) * (bottom - top); };
  auto pxUnits = [&](double u) { return left + (u - xAxis.lo) / (xAxis.hi - xAxis.lo) * (right - left); };
  auto pyUnits = [&](double u) { return bottom - (u - yAxis.lo) / (yAxis.hi - yAxis.lo) * (bottom - top); };

  // Grid and ticks.
  for (double t : ticks(yAxis)) {
    const double y = pyUnits(t);
    canvas.line(left, y, right, y, kGrid);
    const std::string label = tickLabel(yAxis, t);
    canvas.text(left - 8 - Canvas::textWidth(label), y - 6, label, kText);
  }
  if (categorical) {
    for (std::size_t i = 0; i < axes.categories.size(); ++i) {
      const double x = pxUnits(static_cast<double>(i));
      canvas.text(x - Canvas::textWidth(axes.categories[i]) / 2.0, bottom + 10, axes.categories[i], kText);
    }
  } else {
    for (double t : ticks(xAxis)) {
      const double x = pxUnits(t);
      canvas.line(x, top, x, bottom, kGrid);
      const std::string label = tickLabel(xAxis, t);
      canvas.text(x - Canvas::textWidth(label) / 2.0, bottom + 10, label, kText);
    }
  }
  canvas.line(left, top, left, bottom, kBlack);
  canvas.line(left, bottom, right, bottom, kBlack);
  canvas.text((width - Canvas::textWidth(axes.title)) / 2.0, 16, axes.title, kBlack);
  canvas.text((left + right - Canvas::textWidth(axes.xLabel)) / 2.0, height - 32, axes.xLabel, kText);
  canvas.text(10, top - 26, axes.yLabel, kText);

  // Data.
  for (const PlotSeries& s : series) {
    std::vector<std::pair<double, double>> points;
    const std::size_t n = std::min(s.x.size(), s.y.size());
    for (std::size_t i = 0; i < n; ++i)
      if ((categorical || xAxis.accepts(s.x[i])) && yAxis.accepts(s.y[i]))
        points.emplace_back(categorical ? pxUnits(s.x[i]) : px(s.x[i]), py(s.y[i]));
    switch (s.style) {
      case PlotSeries::Style::kDots:
        for (const auto& [x, y] : points)
          canvas.dot(x, y, 3.0, s.color);
        break;
      case PlotSeries::Style::kLine:
        std::sort(points.begin(), points.end());
        for (std::size_t i = 1; i < points.size(); ++i)
          canvas.line(points[i - 1].first, points[i - 1].second, points[i].first, points[i].second, s.color,
                      2);
        break;
      case PlotSeries::Style::kTicks:
        for (const auto& [x, y] : points)
          canvas.line(x - 22, y, x + 22, y, s.color, 3);
        break;
    }
  }

  // Legend, top right, inside the axes.
  double ly = top + 8;
  for (const PlotSeries& s : series) {
    if (s.label.empty()) continue;
    const double lx = right - 16 - Canvas::textWidth(s.label) - 26;
    if (s.style == PlotSeries::Style::kDots)
      canvas.dot(lx + 8, ly + 7, 4.0, s.color);
    else
      canvas.line(lx, ly + 7, lx + 18, ly + 7, s.color, 3);
    canvas.text(lx + 26, ly, s.label, kText);
    ly += 22;
  }
  return canvas.take();
}

}  // namespace shapedb::io
