/**
 * @file figure.hpp
 * @brief Off-screen figures rendered to PNG (OpenCV + FreeType, no display).
 *
 * A Figure is a grid of Axes; each Axes holds line series, shaded bands
 * (confidence intervals, +-sigma envelopes), shaded x-spans (GNSS outages)
 * horizontal reference lines and heat-map cells, on linear or log10 axes
 * (or categorical ones through explicit ticks), with a legend.
 * This module is the only one that includes OpenCV.
 *
 * Conventions: data in any unit (the caller converts to the unit it labels);
 * sizes in pixels; text is UTF-8 (Greek letters, superscripts and U+2212 are
 * in DejaVu Sans). Drawing order inside an axes: grid, spans, bands, hlines,
 * series (in vector order), frame and ticks, legend. Automatic limits cover
 * every finite point (positive only on a log axis) of series, bands, spans and
 * hlines, padded by 5 % on y (log10 space on log axes), 0 % on linear x and
 * 3 % on log x; y limits only consider points whose x is inside the x limits.
 * Dense series (more than 4 points per pixel column) are decimated to first /
 * min / max / last per column, which is visually lossless.
 *
 * Example (log-log wavelet variance with a 95 % CI band):
 * @code
 *   plot::Axes ax;  ax.logx = ax.logy = true;
 *   ax.xlabel = "scale τ [s]";  ax.ylabel = "ν² [(rad/s)²]";
 *   ax.bands.push_back({"95% CI", tau, lo, hi, plot::palette(0), 0.2});
 *   ax.series.push_back({"empirical", tau, nu2, plot::palette(0),
 *                        plot::LineStyle::Solid, plot::Marker::FilledCircle});
 *   plot::Figure fig;  fig.axes = {ax};  plot::savePng(fig, "wv.png");
 * @endcode
 */
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace navimpact::plot {

/// 8-bit sRGB colour.
struct Color {
  std::uint8_t r = 0, g = 0, b = 0;
};
/**
 * Colour-blind-safe qualitative palette (Okabe & Ito 2008), cycled by index:
 * blue, vermillion, bluish green, orange, reddish purple, sky blue, black,
 * yellow (yellow last: it is weak on white).
 * @param[in] i  any integer (negative values wrap too).
 */
Color palette(int i);

/// Stroke pattern, laid out along the line in pixel space (matplotlib's
/// dashed 3.7w on / 1.6w off, dotted round dots every ~2.3w). None: markers only.
enum class LineStyle { Solid, Dashed, Dotted, None };
/// Marker drawn at every data point (radius ~1.4 width + 1.5 px).
enum class Marker { None, Circle, FilledCircle, Square, Cross };
/// Legend placement inside the plot area. Best (the default) picks, among the
/// four corners and then the four edge centres, the place hiding the fewest
/// drawn series/hline pixels (bands count little); ties go to TopRight,
/// TopLeft, BottomLeft, BottomRight. Entries: series, hlines, bands, spans
/// with a non-empty label, in that order.
enum class LegendPos { TopRight, TopLeft, BottomRight, BottomLeft, None, Best };

struct Series {
  std::string label;            ///< legend text ("" = not in legend)
  std::vector<double> x, y;     ///< same length; non-finite points break the line
  Color color{0, 114, 178};
  LineStyle style = LineStyle::Solid;
  Marker marker = Marker::None;
  double width = 2.0;           ///< line width [px], exact (anti-aliased); <= 1.3 draws a hairline
};

/// Filled region between lo(x) and hi(x), alpha-blended over what is below.
/// Non-finite x or hi breaks the band; on a log y axis a non-positive lo
/// extends the band to the bottom edge.
struct Band {
  std::string label;               ///< legend text ("" = not in legend)
  std::vector<double> x, lo, hi;   ///< same length
  Color color{0, 114, 178};
  double alpha = 0.2;           ///< opacity 0..1
};

/// Shaded vertical span x0..x1 over the full height (e.g. a GNSS outage).
struct Span {
  std::string label;       ///< legend text ("" = not in legend)
  double x0 = 0, x1 = 0;   ///< x data units, either order
  Color color{128, 128, 128};
  double alpha = 0.15;
};

/// Horizontal reference line across the plot area (width 1.5 px at 1400x900).
struct HLine {
  std::string label;   ///< legend text ("" = not in legend)
  double y = 0;        ///< y data units
  Color color{0, 0, 0};
  LineStyle style = LineStyle::Dashed;
};

/// Filled rectangle x0..x1 by y0..y1 in data units, drawn opaque with an
/// optional centred one-line text and outline: the cells of a heat map.
/// Cells are drawn after spans and before bands; they count in the automatic
/// limits. The text shrinks (down to 60 %) to fit the cell's width.
struct Cell {
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;  ///< data units, either order
  Color fill{255, 255, 255};
  std::string text;                       ///< "" = none
  Color text_color{34, 34, 34};
  double outline = 0.0;                   ///< outline width [px] inside the cell, 0 = none
  Color outline_color{0, 0, 0};
};

/// An explicit tick: position in data units and its label (categorical axes).
struct TickMark {
  double value = 0;
  std::string label;
};

/// One plot panel.
struct Axes {
  std::string title, xlabel, ylabel;  ///< "" = none (no space is reserved)
  bool logx = false, logy = false;    ///< log10 axes: decades labelled 10^k, minor ticks 2..9
  std::vector<Span> spans;      ///< drawn first
  std::vector<Band> bands;
  std::vector<Series> series;
  std::vector<HLine> hlines;
  std::vector<Cell> cells;      ///< heat-map cells (see Cell)
  /// Explicit ticks replacing the automatic ones (all labelled, no minor ticks);
  /// empty = automatic.
  std::vector<TickMark> xticks, yticks;
  /// Limits (lower < upper; > 0 on log axes); default: data range, see @file.
  std::optional<std::pair<double, double>> xlim, ylim;
  LegendPos legend = LegendPos::Best;  ///< Best: corner hiding the least data
  bool grid = true;  ///< light grid at major ticks (and log minor ticks)
};

/// Grid of axes, row-major; rows * cols == axes.size() (or axes fewer: empty cells).
/// Margins are computed from the text sizes and aligned per row and column.
struct Figure {
  /// Pixels, 100..20000. Fonts scale with sqrt(area / (1400*900)), never below
  /// 0.78: tick labels 17 px, axis labels 18 px, titles 19 px, suptitle 24 px at 1400x900.
  int width = 1400, height = 900;
  std::string title;        ///< figure super-title ("" = none)
  int rows = 1, cols = 1;   ///< grid shape, >= 1
  std::vector<Axes> axes;   ///< row-major, at most rows * cols, at least one
  /// TrueType font used for all text (DejaVu Sans from fonts-dejavu-core).
  std::string font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
};

/// Pixel rectangle of one plot area (inside the axes frame), image coordinates
/// (x to the right, y downwards, origin at the top-left pixel).
struct PixelRect {
  int x = 0, y = 0, width = 0, height = 0;
};

/**
 * Render @p fig and write it as PNG to @p path (PNG whatever the extension).
 * @param[in] fig   the figure.
 * @param[in] path  output file; its folder must exist. Overwritten.
 * @throws navimpact::Error if the font is missing, the layout is invalid
 *         (no axes, too many axes for the grid, bad limits, mismatched vector
 *         lengths, figure too small, non-positive data only on a log axis) or
 *         the file cannot be written; each message names the axes or the path.
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
