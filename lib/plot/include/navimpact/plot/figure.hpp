/**
 * @file figure.hpp
 * @brief Off-screen figures rendered to PNG (OpenCV + FreeType, no display).
 *
 * A Figure is a grid of Axes; each Axes holds line series, shaded bands
 * (confidence intervals, +-sigma envelopes), shaded x-spans (GNSS outages)
 * and horizontal reference lines, on linear or log10 axes, with a legend.
 * This module is the only one that includes OpenCV.
 */
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace navimpact::plot {

struct Color {
  std::uint8_t r = 0, g = 0, b = 0;
};
/// Colour-blind-safe qualitative palette (Okabe-Ito), cycled by index.
Color palette(int i);

enum class LineStyle { Solid, Dashed, Dotted, None };
enum class Marker { None, Circle, FilledCircle, Square, Cross };
/// Legend placement inside the plot area. Best picks the corner covering the
/// fewest drawn data points (ties: TopRight, TopLeft, BottomLeft, BottomRight).
enum class LegendPos { TopRight, TopLeft, BottomRight, BottomLeft, None, Best };

struct Series {
  std::string label;            ///< legend text ("" = not in legend)
  std::vector<double> x, y;     ///< same length; non-finite points break the line
  Color color{0, 114, 178};
  LineStyle style = LineStyle::Solid;
  Marker marker = Marker::None;
  double width = 2.0;           ///< line width [px]
};

/// Filled region between lo(x) and hi(x).
struct Band {
  std::string label;
  std::vector<double> x, lo, hi;
  Color color{0, 114, 178};
  double alpha = 0.2;           ///< opacity 0..1
};

/// Shaded vertical span x0..x1 (e.g. a GNSS outage).
struct Span {
  std::string label;
  double x0 = 0, x1 = 0;
  Color color{128, 128, 128};
  double alpha = 0.15;
};

struct HLine {
  std::string label;
  double y = 0;
  Color color{0, 0, 0};
  LineStyle style = LineStyle::Dashed;
};

struct Axes {
  std::string title, xlabel, ylabel;
  bool logx = false, logy = false;
  std::vector<Span> spans;      ///< drawn first
  std::vector<Band> bands;
  std::vector<Series> series;
  std::vector<HLine> hlines;
  std::optional<std::pair<double, double>> xlim, ylim;  ///< default: data range
  LegendPos legend = LegendPos::Best;  ///< Best: corner hiding the least data
  bool grid = true;
};

/// Grid of axes, row-major; rows * cols == axes.size() (or axes fewer: empty cells).
struct Figure {
  int width = 1400, height = 900;  ///< pixels
  std::string title;
  int rows = 1, cols = 1;
  std::vector<Axes> axes;
  /// TrueType font used for all text (DejaVu Sans from fonts-dejavu-core).
  std::string font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
};

/// Pixel rectangle of one plot area (inside the axes frame), image coordinates
/// (x to the right, y downwards, origin at the top-left pixel).
struct PixelRect {
  int x = 0, y = 0, width = 0, height = 0;
};

/**
 * Render @p fig and write it as PNG to @p path.
 * @throws navimpact::Error if the font is missing, the layout is invalid
 *         (e.g. non-positive data on a log axis only) or the file cannot be written.
 */
void savePng(const Figure& fig, const std::string& path);

/**
 * Layout of @p fig as savePng would draw it, without drawing.
 * @param[in] fig  the figure.
 * @return one rectangle per element of fig.axes: the plot area (data region) in
 *         pixels. A data point (x, y) inside the limits maps linearly (or
 *         log10-linearly) from the left/bottom edge to the right/top edge.
 * @throws navimpact::Error as savePng (font, layout), but never writes.
 */
std::vector<PixelRect> plotAreas(const Figure& fig);

}  // namespace navimpact::plot
