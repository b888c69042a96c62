#pragma once
// Charts for benchmark reports: scatter and line series on linear or logarithmic axes, or dots over
// categories, with ticks, labels and a legend (text by stb_easy_font), drawn into an Image for savePng.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <shapedb/io/render.h>

namespace shapedb::io {

struct PlotSeries {
  std::string label;  ///< in the legend; "" keeps the series out of it
  std::vector<double> x, y;
  std::array<std::uint8_t, 3> color{31, 119, 180};
  enum class Style { kDots, kLine, kTicks } style = Style::kDots;  ///< kTicks: short horizontal bars
};

struct PlotAxes {
  std::string title, xLabel, yLabel;
  bool logX = false, logY = false;  ///< non-positive values are left out on a log axis
  /// Non-empty: x is a category index (0, 1, ...), and these are the names under the axis.
  std::vector<std::string> categories;
};

/// Draws the series on one set of axes fitted to their finite values (padded by 5 %, to decades on a
/// log axis). Points that are not finite are skipped.
Image plotChart(const PlotAxes& axes, std::span<const PlotSeries> series, int width = 900, int height = 560);

}  // namespace shapedb::io
