// Internal: tick locations and tick-label text for linear and log10 axes.
#pragma once

#include <string>
#include <vector>

namespace navimpact::plot::detail {

/// Tick label: main text plus an optional superscript (log decades "10" "-3").
struct TickLabel {
  std::string base;  ///< UTF-8 text at normal size
  std::string sup;   ///< UTF-8 superscript (empty: none)
};

struct Tick {
  double value = 0;      ///< data units
  bool major = true;     ///< major ticks get a grid line and may get a label
  bool labeled = false;  ///< draw the label
  TickLabel label;
};

/// Nice step from {1, 2, 5} x 10^k that is >= @p raw (raw > 0).
double niceStep(double raw);

/**
 * Linear ticks on [lo, hi] with a nice step such that at most about
 * @p maxTicks ticks fall in the range. All ticks are major and labelled.
 */
std::vector<Tick> linearTicks(double lo, double hi, int maxTicks);

/**
 * Log10 ticks on [lo, hi] (0 < lo < hi): decades as majors, labelled every
 * @p labelStride-th decade (exponent divisible by the stride), minor ticks at
 * 2..9 x 10^k when @p withMinor. Falls back to linear nice ticks (placed on the
 * log scale) when the range spans less than one full decade. With
 * @p labelMinor (for axes spanning only about one or two decades, where values
 * lie in 1e-3..1e4) all labels are plain decimals and the minor ticks at 2 and
 * 5 x 10^k are labelled too.
 */
std::vector<Tick> logTicks(double lo, double hi, int labelStride, bool withMinor,
                           int maxLinearTicks, bool labelMinor = false);

/// Format @p v for a linear axis whose tick step is @p step ("0.25", "1e-5").
std::string formatLinear(double v, double step, double maxAbs);

/// Replace a leading ASCII '-' and an exponent '-' with U+2212 (typographic minus).
std::string typographicMinus(const std::string& s);

}  // namespace navimpact::plot::detail
