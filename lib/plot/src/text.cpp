#include "text.hpp"

#include <opencv2/imgproc.hpp>

#include <fstream>

#include "navimpact/core/error.hpp"

namespace navimpact::plot::detail {

TextRenderer::TextRenderer(const std::string& fontPath) {
  std::ifstream probe(fontPath, std::ios::binary);
  if (!probe)
    throw Error("plot: font file '" + fontPath +
                "' cannot be opened (install fonts-dejavu-core or set Figure::font)");
  try {
    ft_ = cv::freetype::createFreeType2();
    ft_->loadFontData(fontPath, 0);
  } catch (const cv::Exception& e) {
    throw Error("plot: font file '" + fontPath + "' is not a usable TrueType font: " + e.what());
  }
}

int TextRenderer::width(const std::string& s, int px) const {
  if (s.empty()) return 0;
  std::string key = std::to_string(px);
  key += '\x1f';
  key += s;
  const auto it = widthCache_.find(key);
  if (it != widthCache_.end()) return it->second;
  int base = 0;
  const int w = ft_->getTextSize(s, px, -1, &base).width;
  widthCache_.emplace(std::move(key), w);
  return w;
}

void TextRenderer::draw(cv::Mat& img, const std::string& s, cv::Point at, int px,
                        const cv::Scalar& bgr, HAlign h, VAlign v) const {
  if (s.empty()) return;
  const int w = width(s, px);
  int x = at.x;
  if (h == HAlign::Center) x -= w / 2;
  else if (h == HAlign::Right) x -= w;
  int y = at.y;  // baseline
  switch (v) {
    case VAlign::Top: y += capHeight(px); break;
    case VAlign::Middle: y += capHeight(px) / 2; break;
    case VAlign::Baseline: break;
    case VAlign::Bottom: y -= descent(px); break;
  }
  // bottomLeftOrigin = true: the origin is the left end of the baseline.
  ft_->putText(img, s, cv::Point(x, y), px, bgr, -1, cv::LINE_AA, true);
}

namespace {
int supPx(int px) { return std::max(6, static_cast<int>(std::lround(0.72 * px))); }
int supRaise(int px) { return static_cast<int>(std::lround(0.42 * px)); }
}  // namespace

int TextRenderer::labelWidth(const TickLabel& l, int px) const {
  int w = width(l.base, px);
  if (!l.sup.empty()) w += 1 + width(l.sup, supPx(px));
  return w;
}

int TextRenderer::labelAscent(const TickLabel& l, int px) const {
  if (l.sup.empty()) return capHeight(px);
  return std::max(capHeight(px), supRaise(px) + capHeight(supPx(px)));
}

void TextRenderer::drawLabel(cv::Mat& img, const TickLabel& l, cv::Point at, int px,
                             const cv::Scalar& bgr, HAlign h, VAlign v) const {
  const int w = labelWidth(l, px);
  int x = at.x;
  if (h == HAlign::Center) x -= w / 2;
  else if (h == HAlign::Right) x -= w;
  int y = at.y;
  switch (v) {
    case VAlign::Top: y += labelAscent(l, px); break;
    case VAlign::Middle: y += capHeight(px) / 2; break;
    case VAlign::Baseline: break;
    case VAlign::Bottom: y -= descent(px); break;
  }
  draw(img, l.base, cv::Point(x, y), px, bgr, HAlign::Left, VAlign::Baseline);
  if (!l.sup.empty())
    draw(img, l.sup, cv::Point(x + width(l.base, px) + 1, y - supRaise(px)), supPx(px), bgr,
         HAlign::Left, VAlign::Baseline);
}

void TextRenderer::drawVertical(cv::Mat& img, const std::string& s, cv::Point at, int px,
                                const cv::Scalar& bgr) const {
  if (s.empty()) return;
  const int w = width(s, px);
  const int hbox = capHeight(px) + descent(px) + 4;
  // Target region on the canvas (rotated text box), clipped to the image.
  cv::Rect target(at.x - 2, at.y - w / 2 - 2, hbox, w + 4);
  target &= cv::Rect(0, 0, img.cols, img.rows);
  if (target.empty()) return;
  // Rotate the background clockwise to horizontal, write, rotate back: the
  // glyphs blend onto the real background.
  cv::Mat horiz;
  cv::rotate(img(target), horiz, cv::ROTATE_90_CLOCKWISE);
  // horiz(i, j) is canvas(target.y + target.height - 1 - j, target.x + i): the
  // text runs up the canvas and its cap top faces left.
  const int hx = target.y + target.height - 1 - (at.y + w / 2);
  const int hy = at.x - target.x + capHeight(px);
  ft_->putText(horiz, s, cv::Point(hx, hy), px, bgr, -1, cv::LINE_AA, true);
  cv::Mat back;
  cv::rotate(horiz, back, cv::ROTATE_90_COUNTERCLOCKWISE);
  back.copyTo(img(target));
}

}  // namespace navimpact::plot::detail
