// Internal: anti-aliased TrueType text on an OpenCV canvas (FreeType2 +
// HarfBuzz through opencv_contrib's freetype module), with simple alignment,
// superscripts and 90-degree rotation.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/freetype.hpp>

#include <string>
#include <unordered_map>

#include "ticks.hpp"

namespace navimpact::plot::detail {

enum class HAlign { Left, Center, Right };
enum class VAlign { Top, Middle, Baseline, Bottom };

class TextRenderer {
 public:
  /// Load @p fontPath; throws navimpact::Error naming the path when missing/invalid.
  explicit TextRenderer(const std::string& fontPath);

  /// Advance width of @p s at em size @p px [pixels].
  int width(const std::string& s, int px) const;
  /// Ink cap height (digits, capitals) at em size @p px.
  static int capHeight(int px) { return static_cast<int>(std::lround(0.73 * px)); }
  /// Descender depth at em size @p px.
  static int descent(int px) { return static_cast<int>(std::lround(0.24 * px)); }

  /**
   * Draw @p s anchored at @p at: HAlign picks the left edge / centre / right
   * edge of the advance box; VAlign picks the cap top, cap middle, baseline or
   * descender bottom.
   */
  void draw(cv::Mat& img, const std::string& s, cv::Point at, int px, const cv::Scalar& bgr,
            HAlign h, VAlign v) const;

  /// Width of a tick label (base + superscript) at em size @p px.
  int labelWidth(const TickLabel& l, int px) const;
  /// Height above the baseline of a tick label (cap height, or superscript top).
  int labelAscent(const TickLabel& l, int px) const;
  /// Draw a tick label; alignment refers to the base text's cap box.
  void drawLabel(cv::Mat& img, const TickLabel& l, cv::Point at, int px, const cv::Scalar& bgr,
                 HAlign h, VAlign v) const;

  /// Draw @p s rotated 90 degrees counter-clockwise (reads bottom to top),
  /// centred vertically on @p at.y, with the cap top at x = @p at.x.
  void drawVertical(cv::Mat& img, const std::string& s, cv::Point at, int px,
                    const cv::Scalar& bgr) const;

 private:
  cv::Ptr<cv::freetype::FreeType2> ft_;
  // getTextSize shapes the text with HarfBuzz (~0.2 ms a call); layout asks
  // for the same label widths many times.
  mutable std::unordered_map<std::string, int> widthCache_;
};

}  // namespace navimpact::plot::detail
