// Off-screen figure rendering with OpenCV: layout (margins from text sizes),
// axis scales (linear / log10), decimated anti-aliased polylines, dashing in
// pixel space, translucent bands and spans, legends, PNG output.
#include "navimpact/plot/figure.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <tuple>

#include "navimpact/core/error.hpp"
#include "text.hpp"
#include "ticks.hpp"

namespace navimpact::plot {

Color palette(int i) {
  // Okabe & Ito (2008), ordered so that the low-contrast yellow comes last.
  static const std::array<Color, 8> kOkabeIto{{{0, 114, 178},    // blue
                                               {213, 94, 0},     // vermillion
                                               {0, 158, 115},    // bluish green
                                               {230, 159, 0},    // orange
                                               {204, 121, 167},  // reddish purple
                                               {86, 180, 233},   // sky blue
                                               {0, 0, 0},        // black
                                               {240, 228, 66}}}; // yellow
  const int n = static_cast<int>(kOkabeIto.size());
  return kOkabeIto[static_cast<std::size_t>(((i % n) + n) % n)];
}

namespace {

using detail::HAlign;
using detail::TextRenderer;
using detail::Tick;
using detail::VAlign;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;
constexpr int kShift = 4;  // fixed-point bits for sub-pixel drawing
constexpr double kOne = 1 << kShift;

cv::Scalar bgr(const Color& c) { return cv::Scalar(c.b, c.g, c.r); }
const cv::Scalar kInk(34, 34, 34);
const cv::Scalar kGridMajor(222, 222, 222);
const cv::Scalar kGridMinor(243, 243, 243);

std::string axesName(const Axes& ax, std::size_t i) {
  std::string s = "plot: axes " + std::to_string(i);
  if (!ax.title.empty()) s += " ('" + ax.title + "')";
  return s;
}

/// Font and spacing sizes [px], scaled with the figure area.
struct Sizes {
  double s = 1;
  int tick = 17, label = 18, title = 19, sup = 24, legend = 16;
  int pad = 10, tickLen = 6, minorLen = 3, gap = 5, labelGap = 8;
  explicit Sizes(const Figure& fig) {
    s = std::clamp(std::sqrt(double(fig.width) * fig.height / (1400.0 * 900.0)), 0.55, 3.0);
    auto sc = [&](double v) { return std::max(1, static_cast<int>(std::lround(v * s))); };
    // Text shrinks less than the figure so that small figures stay readable.
    const double f = std::max(0.78, s);
    auto fs = [&](double v) { return static_cast<int>(std::lround(v * f)); };
    tick = fs(17);
    label = fs(18);
    title = fs(19);
    sup = fs(24);
    legend = fs(16);
    pad = sc(10);
    tickLen = sc(6);
    minorLen = sc(3.5);
    gap = sc(5);
    labelGap = sc(8);
  }
};

/// Data-to-pixel map of one axis. Pixel coordinates are continuous: the lower
/// limit maps to p0, the upper to p1 (the plot-area edges).
struct Scale {
  bool log = false;
  double lo = 0, hi = 1;  // data units
  double p0 = 0, p1 = 1;  // pixels
  double t(double v) const {
    if (!std::isfinite(v)) return kNaN;
    if (log) return v > 0 ? std::log10(v) : kNaN;
    return v;
  }
  double px(double v) const {
    const double t0 = t(lo), t1 = t(hi);
    return p0 + (t(v) - t0) / (t1 - t0) * (p1 - p0);
  }
};

bool validOn(double v, bool log) { return std::isfinite(v) && (!log || v > 0); }

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return !(hi >= lo); }
};

/// Pad the data range by @p frac of its width (in log10 space on log axes).
std::pair<double, double> padRange(Range r, bool log, double frac) {
  if (r.empty()) return log ? std::make_pair(1.0, 10.0) : std::make_pair(0.0, 1.0);
  if (log) {
    double a = std::log10(r.lo), b = std::log10(r.hi);
    if (b - a < 1e-12) {
      a -= 0.5;
      b += 0.5;
    } else {
      const double d = (b - a) * frac;
      a -= d;
      b += d;
    }
    return {std::pow(10.0, a), std::pow(10.0, b)};
  }
  double a = r.lo, b = r.hi;
  if (b - a <= 1e-12 * std::max(1.0, std::abs(a))) {
    const double d = std::max(0.5, 0.1 * std::abs(a));
    return {a - d, b + d};
  }
  const double d = (b - a) * frac;
  return {a - d, b + d};
}

/// The values one axis' limits come from: a finite value is remembered (a
/// log axis with finite values but no positive one is an error), a valid one
/// (finite, positive on a log axis) widens the range.
struct AxisValues {
  explicit AxisValues(bool log_axis) : log(log_axis) {}
  bool log;
  Range r;
  bool anyFinite = false;
  void add(double v) {
    if (std::isfinite(v)) anyFinite = true;
    if (validOn(v, log)) r.add(v);
  }
  /// The padded range; @throws Error on a log axis with finite values but none positive.
  std::pair<double, double> limits(const std::string& where, const char* axis, double pad) const {
    if (r.empty() && anyFinite && log)
      throw Error(where + ": log " + axis + " axis but no positive finite " + axis + " value to plot");
    return padRange(r, log, pad);
  }
};

std::pair<double, double> checkedLim(const std::pair<double, double>& lim, bool log,
                                     const std::string& where, const char* axis) {
  if (!std::isfinite(lim.first) || !std::isfinite(lim.second) || !(lim.second > lim.first))
    throw Error(where + ": " + axis + "lim must be finite with lower < upper (got " +
                std::to_string(lim.first) + ", " + std::to_string(lim.second) + ")");
  if (log && !(lim.first > 0))
    throw Error(where + ": " + axis + "lim must be positive on a log axis (got " +
                std::to_string(lim.first) + ")");
  return lim;
}

/// Axis limits from the data (series, bands, spans, hlines) or the overrides.
void computeLimits(const Axes& ax, std::size_t index, Scale& xs, Scale& ys) {
  const std::string where = axesName(ax, index);
  xs.log = ax.logx;
  ys.log = ax.logy;
  for (const auto& s : ax.series)
    if (s.x.size() != s.y.size())
      throw Error(where + ": series '" + s.label + "' has " + std::to_string(s.x.size()) +
                  " x values but " + std::to_string(s.y.size()) + " y values");
  for (const auto& b : ax.bands)
    if (b.x.size() != b.lo.size() || b.x.size() != b.hi.size())
      throw Error(where + ": band '" + b.label + "' has x, lo, hi of different lengths");

  if (ax.xlim) {
    std::tie(xs.lo, xs.hi) = checkedLim(*ax.xlim, ax.logx, where, "x");
  } else {
    AxisValues x{ax.logx};
    for (const auto& s : ax.series)
      for (std::size_t i = 0; i < s.x.size(); ++i) {  // a point counts where both coordinates do
        if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) x.anyFinite = true;
        if (validOn(s.x[i], ax.logx) && validOn(s.y[i], ax.logy)) x.r.add(s.x[i]);
      }
    for (const auto& b : ax.bands)
      for (double v : b.x) x.add(v);
    for (const auto& sp : ax.spans)  // spans widen the range but do not make a log axis an error
      for (double v : {sp.x0, sp.x1})
        if (validOn(v, ax.logx)) x.r.add(v);
    for (const auto& c : ax.cells)
      for (double v : {c.x0, c.x1}) x.add(v);
    std::tie(xs.lo, xs.hi) = x.limits(where, "x", ax.logx ? 0.03 : 0.0);
  }

  if (ax.ylim) {
    std::tie(ys.lo, ys.hi) = checkedLim(*ax.ylim, ax.logy, where, "y");
  } else {
    AxisValues y{ax.logy};
    auto inX = [&](double x) { return validOn(x, ax.logx) && x >= xs.lo && x <= xs.hi; };
    for (const auto& s : ax.series)
      for (std::size_t i = 0; i < s.x.size(); ++i) {  // every finite y counts, the range only within the x limits
        if (std::isfinite(s.y[i])) y.anyFinite = true;
        if (inX(s.x[i]) && validOn(s.y[i], ax.logy)) y.r.add(s.y[i]);
      }
    for (const auto& b : ax.bands)
      for (std::size_t i = 0; i < b.x.size(); ++i)
        if (inX(b.x[i])) {
          y.add(b.lo[i]);
          y.add(b.hi[i]);
        }
    for (const auto& h : ax.hlines) y.add(h.y);
    for (const auto& c : ax.cells)
      for (double v : {c.y0, c.y1}) y.add(v);
    std::tie(ys.lo, ys.hi) = y.limits(where, "y", 0.05);
  }
}

/// Ticks of one axis whose labels do not collide at pixel length @p len.
std::vector<Tick> chooseTicks(const Scale& sc, double len, bool isX, const TextRenderer& tr,
                              int px) {
  auto fits = [&](const std::vector<Tick>& ticks) {
    double prevPos = kNaN, prevHalf = 0;
    Scale u = sc;
    u.p0 = 0;
    u.p1 = len;
    for (const auto& t : ticks) {
      if (!t.labeled) continue;
      const double pos = u.px(t.value);
      const double half = isX ? 0.5 * tr.labelWidth(t.label, px)
                              : 0.5 * (tr.labelAscent(t.label, px) + TextRenderer::descent(px));
      const double need = isX ? prevHalf + half + 1.0 * px : prevHalf + half + 1.1 * px;
      if (std::isfinite(prevPos) && std::abs(pos - prevPos) < need) return false;
      prevPos = pos;
      prevHalf = half;
    }
    return true;
  };
  const int nMax = std::clamp(static_cast<int>(len / (isX ? 55.0 : 30.0)), 2, isX ? 12 : 10);
  if (sc.log && std::floor(std::log10(sc.hi) + 1e-9) - std::ceil(std::log10(sc.lo) - 1e-9) >= 1) {
    const double decades = std::log10(sc.hi / sc.lo);
    const bool minor = len / decades >= 30.0;
    // Few decades in plain-number territory: label 2 and 5 x 10^k as well.
    if (decades <= 2.5 && sc.lo >= 1e-3 && sc.hi <= 1e4) {
      auto t = detail::logTicks(sc.lo, sc.hi, 1, true, nMax, true);
      if (fits(t)) return t;
    }
    for (int stride : {1, 2, 3, 4, 5, 10, 20, 50, 100}) {
      auto t = detail::logTicks(sc.lo, sc.hi, stride, minor, nMax);
      if (fits(t)) return t;
    }
    return detail::logTicks(sc.lo, sc.hi, 1000, minor, nMax);
  }
  for (int n = nMax; n >= 1; --n) {
    auto t = sc.log ? detail::logTicks(sc.lo, sc.hi, 1, false, n) : detail::linearTicks(sc.lo, sc.hi, n);
    if (fits(t)) return t;
  }
  return sc.log ? detail::logTicks(sc.lo, sc.hi, 1, false, 1) : detail::linearTicks(sc.lo, sc.hi, 1);
}

/// Ticks given by the caller (categorical axes): all major and labelled.
std::vector<Tick> explicitTicks(const std::vector<TickMark>& marks) {
  std::vector<Tick> out;
  for (const auto& m : marks) {
    Tick t;
    t.value = m.value;
    t.major = true;
    t.labeled = true;
    t.label.base = m.label;
    out.push_back(t);
  }
  return out;
}

struct Margins {
  int left = 0, right = 0, top = 0, bottom = 0;
};

struct Panel {
  const Axes* ax = nullptr;
  std::size_t index = 0;
  int row = 0, col = 0;
  cv::Rect cell, area;
  Scale xs, ys;
  std::vector<Tick> xt, yt;
  Margins need;
};

struct Layout {
  Sizes sz;
  int topBand = 0;
  std::vector<Panel> panels;
  explicit Layout(const Figure& f) : sz(f) {}
};

Margins marginsFor(const Panel& p, const Sizes& sz, const TextRenderer& tr) {
  Margins m;
  const Axes& ax = *p.ax;
  int yw = 0;
  for (const auto& t : p.yt)
    if (t.labeled) yw = std::max(yw, tr.labelWidth(t.label, sz.tick));
  int xh = 0;
  for (const auto& t : p.xt)
    if (t.labeled) xh = std::max(xh, tr.labelAscent(t.label, sz.tick));
  xh += TextRenderer::descent(sz.tick);
  const int labelH = TextRenderer::capHeight(sz.label) + TextRenderer::descent(sz.label);
  m.left = sz.pad + (ax.ylabel.empty() ? 0 : labelH + sz.labelGap) + yw + sz.gap + sz.tickLen;
  m.bottom = sz.tickLen + sz.gap + xh + (ax.xlabel.empty() ? 0 : sz.labelGap + labelH) + sz.pad;
  const int titleH = TextRenderer::capHeight(sz.title) + TextRenderer::descent(sz.title);
  m.top = sz.pad + (ax.title.empty() ? TextRenderer::capHeight(sz.tick) / 2 : titleH + sz.labelGap);
  // The last x label may stick out to the right of the plot area.
  m.right = sz.pad + sz.gap;
  const double len = std::max(1, p.area.width);
  Scale u = p.xs;
  u.p0 = 0;
  u.p1 = len;
  for (const auto& t : p.xt)
    if (t.labeled) {
      const double over = u.px(t.value) + 0.5 * tr.labelWidth(t.label, sz.tick) - len;
      m.right = std::max(m.right, static_cast<int>(std::ceil(over)) + sz.gap);
    }
  return m;
}

Layout computeLayout(const Figure& fig, const TextRenderer& tr) {
  if (fig.axes.empty()) throw Error("plot: figure '" + fig.title + "' has no axes (empty figure)");
  if (fig.rows < 1 || fig.cols < 1)
    throw Error("plot: figure grid must be at least 1x1 (got " + std::to_string(fig.rows) + "x" +
                std::to_string(fig.cols) + ")");
  if (fig.axes.size() > static_cast<std::size_t>(fig.rows) * fig.cols)
    throw Error("plot: figure has " + std::to_string(fig.axes.size()) + " axes but a " +
                std::to_string(fig.rows) + "x" + std::to_string(fig.cols) + " grid");
  if (fig.width < 100 || fig.height < 100 || fig.width > 20000 || fig.height > 20000)
    throw Error("plot: figure size " + std::to_string(fig.width) + "x" +
                std::to_string(fig.height) + " px is outside 100..20000");
  Layout L(fig);
  const Sizes& sz = L.sz;
  L.topBand = fig.title.empty()
                  ? 0
                  : sz.pad + TextRenderer::capHeight(sz.sup) + TextRenderer::descent(sz.sup) + sz.gap;
  const double cw = double(fig.width) / fig.cols;
  const double ch = double(fig.height - L.topBand) / fig.rows;
  for (std::size_t i = 0; i < fig.axes.size(); ++i) {
    Panel p;
    p.ax = &fig.axes[i];
    p.index = i;
    p.row = static_cast<int>(i) / fig.cols;
    p.col = static_cast<int>(i) % fig.cols;
    const int x0 = static_cast<int>(std::lround(p.col * cw));
    const int x1 = static_cast<int>(std::lround((p.col + 1) * cw));
    const int y0 = L.topBand + static_cast<int>(std::lround(p.row * ch));
    const int y1 = L.topBand + static_cast<int>(std::lround((p.row + 1) * ch));
    p.cell = cv::Rect(x0, y0, x1 - x0, y1 - y0);
    computeLimits(*p.ax, i, p.xs, p.ys);
    p.area = cv::Rect(x0 + 80, y0 + 40, std::max(20, p.cell.width - 100),
                      std::max(20, p.cell.height - 100));
    L.panels.push_back(p);
  }
  // Margins aligned per column (left/right) and per row (top/bottom); two
  // passes because tick density depends on the plot size and vice versa.
  std::vector<Margins> keep(fig.axes.size());
  for (int pass = 0; pass < 3; ++pass) {
    for (auto& p : L.panels) {
      p.xt = p.ax->xticks.empty() ? chooseTicks(p.xs, p.area.width, true, tr, sz.tick) : explicitTicks(p.ax->xticks);
      p.yt = p.ax->yticks.empty() ? chooseTicks(p.ys, p.area.height, false, tr, sz.tick)
                                  : explicitTicks(p.ax->yticks);
      if (pass == 2) continue;
      Margins m = marginsFor(p, sz, tr);
      Margins& k = keep[p.index];
      k.left = std::max(k.left, m.left);
      k.right = std::max(k.right, m.right);
      k.top = std::max(k.top, m.top);
      k.bottom = std::max(k.bottom, m.bottom);
      p.need = k;
    }
    if (pass == 2) break;
    std::vector<int> left(fig.cols, 0), right(fig.cols, 0), top(fig.rows, 0), bottom(fig.rows, 0);
    for (const auto& p : L.panels) {
      left[p.col] = std::max(left[p.col], p.need.left);
      right[p.col] = std::max(right[p.col], p.need.right);
      top[p.row] = std::max(top[p.row], p.need.top);
      bottom[p.row] = std::max(bottom[p.row], p.need.bottom);
    }
    for (auto& p : L.panels) {
      const int w = p.cell.width - left[p.col] - right[p.col];
      const int h = p.cell.height - top[p.row] - bottom[p.row];
      if (w < 30 || h < 30)
        throw Error(axesName(*p.ax, p.index) + ": figure " + std::to_string(fig.width) + "x" +
                    std::to_string(fig.height) + " px is too small for a " +
                    std::to_string(fig.rows) + "x" + std::to_string(fig.cols) +
                    " grid with these labels");
      p.area = cv::Rect(p.cell.x + left[p.col], p.cell.y + top[p.row], w, h);
    }
  }
  for (auto& p : L.panels) {
    p.xs.p0 = p.area.x - 0.5;
    p.xs.p1 = p.area.x + p.area.width - 0.5;
    p.ys.p0 = p.area.y + p.area.height - 0.5;
    p.ys.p1 = p.area.y - 0.5;
  }
  return L;
}

// ---------------------------------------------------------------- geometry --

using Run = std::vector<cv::Point2d>;

/// Liang-Barsky clip of segment a-b to rectangle r; false when fully outside.
bool clipSegment(cv::Point2d& a, cv::Point2d& b, const cv::Rect2d& r) {
  double t0 = 0, t1 = 1;
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {a.x - r.x, r.x + r.width - a.x, a.y - r.y, r.y + r.height - a.y};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0) {
      if (q[i] < 0) return false;
    } else {
      const double t = q[i] / p[i];
      if (p[i] < 0) t0 = std::max(t0, t);
      else t1 = std::min(t1, t);
    }
  }
  if (t0 > t1) return false;
  const cv::Point2d a0 = a;
  a = a0 + t0 * cv::Point2d(dx, dy);
  b = a0 + t1 * cv::Point2d(dx, dy);
  return true;
}

/// Clip polylines to @p r, splitting a run where it leaves the rectangle.
std::vector<Run> clipRuns(const std::vector<Run>& runs, const cv::Rect2d& r) {
  std::vector<Run> out;
  for (const auto& run : runs) {
    if (run.size() == 1) {
      if (r.contains(run[0])) out.push_back(run);
      continue;
    }
    Run cur;
    for (std::size_t i = 1; i < run.size(); ++i) {
      cv::Point2d a = run[i - 1], b = run[i];
      if (!clipSegment(a, b, r)) {
        if (cur.size() > 1) out.push_back(std::move(cur));
        cur.clear();
        continue;
      }
      if (cur.empty() || cur.back() != a) {
        if (cur.size() > 1) out.push_back(std::move(cur));
        cur.clear();
        cur.push_back(a);
      }
      cur.push_back(b);
      if (b != run[i]) {  // left the rectangle
        out.push_back(std::move(cur));
        cur.clear();
      }
    }
    if (cur.size() > 1) out.push_back(std::move(cur));
  }
  return out;
}

/// Keep first, min, max and last point per pixel column of consecutive points
/// (M4 aggregation): visually lossless for dense data.
Run decimate(const Run& run, int width) {
  if (run.size() <= static_cast<std::size_t>(4 * std::max(width, 1))) return run;
  Run out;
  out.reserve(static_cast<std::size_t>(4 * width + 8));
  std::size_t i = 0;
  while (i < run.size()) {
    const double col = std::floor(run[i].x);
    std::size_t j = i, iMin = i, iMax = i;
    while (j < run.size() && std::floor(run[j].x) == col) {
      if (run[j].y < run[iMin].y) iMin = j;
      if (run[j].y > run[iMax].y) iMax = j;
      ++j;
    }
    std::array<std::size_t, 4> idx{i, std::min(iMin, iMax), std::max(iMin, iMax), j - 1};
    std::size_t last = static_cast<std::size_t>(-1);
    for (std::size_t k : idx)
      if (k != last) {
        out.push_back(run[k]);
        last = k;
      }
    i = j;
  }
  return out;
}

cv::Point fixedPt(const cv::Point2d& p) {
  return cv::Point(static_cast<int>(std::lround(p.x * kOne)), static_cast<int>(std::lround(p.y * kOne)));
}

/// Sutherland-Hodgman clip of a polygon to a rectangle.
std::vector<cv::Point2d> clipPolygon(std::vector<cv::Point2d> poly, const cv::Rect2d& r) {
  auto clipEdge = [](const std::vector<cv::Point2d>& in, auto inside, auto cut) {
    std::vector<cv::Point2d> out;
    if (in.empty()) return out;
    cv::Point2d prev = in.back();
    for (const auto& cur : in) {
      const bool ci = inside(cur), pi = inside(prev);
      if (ci) {
        if (!pi) out.push_back(cut(prev, cur));
        out.push_back(cur);
      } else if (pi) {
        out.push_back(cut(prev, cur));
      }
      prev = cur;
    }
    return out;
  };
  const double x0 = r.x, x1 = r.x + r.width, y0 = r.y, y1 = r.y + r.height;
  auto atX = [](double x) {
    return [x](const cv::Point2d& a, const cv::Point2d& b) {
      const double t = (x - a.x) / (b.x - a.x);
      return cv::Point2d(x, a.y + t * (b.y - a.y));
    };
  };
  auto atY = [](double y) {
    return [y](const cv::Point2d& a, const cv::Point2d& b) {
      const double t = (y - a.y) / (b.y - a.y);
      return cv::Point2d(a.x + t * (b.x - a.x), y);
    };
  };
  poly = clipEdge(poly, [&](const cv::Point2d& p) { return p.x >= x0; }, atX(x0));
  poly = clipEdge(poly, [&](const cv::Point2d& p) { return p.x <= x1; }, atX(x1));
  poly = clipEdge(poly, [&](const cv::Point2d& p) { return p.y >= y0; }, atY(y0));
  poly = clipEdge(poly, [&](const cv::Point2d& p) { return p.y <= y1; }, atY(y1));
  return poly;
}

/// Fill polygons (fixed-point, relative to @p roi) blended with opacity @p alpha.
void blendFill(cv::Mat& roi, const std::vector<std::vector<cv::Point>>& polys,
               const cv::Scalar& color, double alpha) {
  if (polys.empty()) return;
  int x0 = INT32_MAX, y0 = INT32_MAX, x1 = INT32_MIN, y1 = INT32_MIN;
  for (const auto& poly : polys)
    for (const auto& p : poly) {
      x0 = std::min(x0, p.x >> kShift);
      y0 = std::min(y0, p.y >> kShift);
      x1 = std::max(x1, (p.x >> kShift) + 1);
      y1 = std::max(y1, (p.y >> kShift) + 1);
    }
  cv::Rect bb = cv::Rect(x0 - 1, y0 - 1, x1 - x0 + 3, y1 - y0 + 3) & cv::Rect(0, 0, roi.cols, roi.rows);
  if (bb.empty()) return;
  cv::Mat dst = roi(bb);
  cv::Mat overlay = dst.clone();
  std::vector<std::vector<cv::Point>> shifted = polys;
  for (auto& poly : shifted)
    for (auto& p : poly) p -= cv::Point(bb.x << kShift, bb.y << kShift);
  cv::fillPoly(overlay, shifted, color, cv::LINE_AA, kShift);
  alpha = std::clamp(alpha, 0.0, 1.0);
  cv::addWeighted(overlay, alpha, dst, 1.0 - alpha, 0.0, dst);
}

/// Segment a-b as an anti-aliased quad of exact width @p w [px] (butt caps).
/// OpenCV's own thick AA lines only come in ~2 px steps (1.4, 3.4, 5.4 px).
void thickSegment(cv::Mat& img, const cv::Point2d& a, const cv::Point2d& b, double w,
                  const cv::Scalar& color) {
  const cv::Point2d d = b - a;
  const double len = cv::norm(d);
  if (len < 1e-9) return;
  const cv::Point2d n = cv::Point2d(-d.y, d.x) * (0.5 * w / len);
  const cv::Point q[4] = {fixedPt(a + n), fixedPt(b + n), fixedPt(b - n), fixedPt(a - n)};
  cv::fillConvexPoly(img, q, 4, color, cv::LINE_AA, kShift);
}

void dot(cv::Mat& img, const cv::Point2d& c, double diameter, const cv::Scalar& color) {
  cv::circle(img, fixedPt(c), static_cast<int>(std::lround(0.5 * diameter * kOne)), color, cv::FILLED,
             cv::LINE_AA, kShift);
}

/// Solid polyline of width @p w with round joins.
void solidPolyline(cv::Mat& img, const Run& run, double w, const cv::Scalar& color) {
  if (w <= 1.3) {  // hairline: OpenCV's 1-px anti-aliased line
    std::vector<cv::Point> pts;
    pts.reserve(run.size());
    for (const auto& p : run) pts.push_back(fixedPt(p));
    cv::polylines(img, pts, false, color, 1, cv::LINE_AA, kShift);
    return;
  }
  for (std::size_t i = 1; i < run.size(); ++i) {
    thickSegment(img, run[i - 1], run[i], w, color);
    if (i + 1 == run.size()) break;
    // Round join where the direction turns by more than ~10 degrees (smaller
    // turns leave no visible notch between the butt ends).
    const cv::Point2d d1 = run[i] - run[i - 1], d2 = run[i + 1] - run[i];
    const double n1 = cv::norm(d1), n2 = cv::norm(d2);
    if (n1 * n2 == 0 || d1.dot(d2) < 0.985 * n1 * n2) dot(img, run[i], w, color);
  }
}

/// Stroke a polyline with a solid, dashed or dotted pattern laid out along
/// its length in pixel space (the pattern continues across vertices).
/// Dash lengths follow matplotlib's scaled patterns: dashed 3.7w on, 1.6w off.
void stroke(cv::Mat& img, const Run& run, const cv::Scalar& color, double width, LineStyle style) {
  if (style == LineStyle::None || run.size() < 2) return;
  const double w = std::max(1.0, width);
  if (style == LineStyle::Solid) {
    solidPolyline(img, run, w, color);
    return;
  }
  const bool dotted = style == LineStyle::Dotted;
  const double on = dotted ? 0.0 : std::max(4.0, 3.7 * w);
  const double off = dotted ? std::max(3.5, 2.3 * w) : std::max(3.0, 1.6 * w);
  double phase = 0;  // distance into the current on+off period
  for (std::size_t i = 1; i < run.size(); ++i) {
    const cv::Point2d a = run[i - 1], b = run[i];
    const double len = cv::norm(b - a);
    if (len <= 0) continue;
    const cv::Point2d dir = (b - a) / len;
    double s = 0;
    while (s < len) {
      if (dotted) {
        if (phase == 0) dot(img, a + dir * s, std::max(1.6, 1.15 * w), color);
        const double step = std::min(off - phase, len - s);
        s += step;
        phase += step;
        if (phase >= off - 1e-12) phase = 0;
        continue;
      }
      const bool drawing = phase < on;
      const double remain = drawing ? on - phase : on + off - phase;
      const double step = std::min(remain, len - s);
      if (drawing) {
        if (w <= 1.3)
          cv::line(img, fixedPt(a + dir * s), fixedPt(a + dir * (s + step)), color, 1, cv::LINE_AA, kShift);
        else
          thickSegment(img, a + dir * s, a + dir * (s + step), w, color);
      }
      s += step;
      phase += step;
      if (phase >= on + off - 1e-12) phase = 0;
    }
  }
}

void drawMarker(cv::Mat& img, const cv::Point2d& c, Marker m, const cv::Scalar& color, double width) {
  const double r = std::max(3.0, 1.4 * width + 1.5);
  const double lw = std::max(1.3, 0.75 * width);
  switch (m) {
    case Marker::None: break;
    case Marker::Circle: {
      // Ring of exact width lw, as a closed thick polyline.
      Run ring;
      for (int k = 0; k <= 25; ++k) {
        const double t = 2 * kPi * k / 24;
        ring.push_back(c + cv::Point2d(std::cos(t), std::sin(t)) * (r - 0.5 * lw));
      }
      solidPolyline(img, ring, lw, color);
      break;
    }
    case Marker::FilledCircle: dot(img, c, 2 * r, color); break;
    case Marker::Square: {
      const double q = 0.85 * r - 0.5 * lw;
      const Run sq{c + cv::Point2d(-q, -q), c + cv::Point2d(q, -q), c + cv::Point2d(q, q),
                   c + cv::Point2d(-q, q), c + cv::Point2d(-q, -q), c + cv::Point2d(q, -q)};
      solidPolyline(img, sq, lw, color);
      break;
    }
    case Marker::Cross: {
      const double q = 0.8 * r;
      thickSegment(img, c + cv::Point2d(-q, -q), c + cv::Point2d(q, q), lw, color);
      thickSegment(img, c + cv::Point2d(-q, q), c + cv::Point2d(q, -q), lw, color);
      break;
    }
  }
}

// ------------------------------------------------------------------ legend --

struct LegendEntry {
  enum Kind { Line, Patch } kind = Line;
  std::string label;
  Color color;
  LineStyle style = LineStyle::Solid;
  Marker marker = Marker::None;
  double width = 2;
  double alpha = 1;
};

std::vector<LegendEntry> legendEntries(const Axes& ax) {
  std::vector<LegendEntry> e;
  for (const auto& s : ax.series)
    if (!s.label.empty()) e.push_back({LegendEntry::Line, s.label, s.color, s.style, s.marker, s.width, 1});
  for (const auto& h : ax.hlines)
    if (!h.label.empty()) e.push_back({LegendEntry::Line, h.label, h.color, h.style, Marker::None, 1.5, 1});
  for (const auto& b : ax.bands)
    if (!b.label.empty())
      e.push_back({LegendEntry::Patch, b.label, b.color, LineStyle::None, Marker::None, 0, b.alpha});
  for (const auto& sp : ax.spans)
    if (!sp.label.empty())
      e.push_back({LegendEntry::Patch, sp.label, sp.color, LineStyle::None, Marker::None, 0, sp.alpha});
  return e;
}

// ---------------------------------------------------------------- drawing --

/// Font size <= @p px (down to 60 %) at which @p s fits in @p maxWidth pixels.
int fitPx(const TextRenderer& tr, const std::string& s, int px, int maxWidth) {
  const int minPx = std::max(8, static_cast<int>(0.6 * px));
  while (px > minPx && tr.width(s, px) > maxWidth) --px;
  return px;
}

class PanelPainter {
 public:
  PanelPainter(cv::Mat& canvas, const Panel& p, const Sizes& sz, const TextRenderer& tr)
      : canvas_(canvas), p_(p), ax_(*p.ax), sz_(sz), tr_(tr), roi_(canvas(p.area)) {
    if (ax_.legend == LegendPos::Best) occupancy_ = cv::Mat::zeros(roi_.size(), CV_8U);
  }

  void draw() {
    if (ax_.grid) drawGrid();
    drawSpans();
    drawCells();
    drawBands();
    drawHLines();
    drawSeries();
    drawFrameAndTicks();
    drawLabels();
    drawLegend();
  }

 private:
  double X(double v) const { return p_.xs.px(v) - p_.area.x; }
  double Y(double v) const { return p_.ys.px(v) - p_.area.y; }
  cv::Rect2d clipRect(double margin) const {
    return cv::Rect2d(-margin, -margin, roi_.cols + 2 * margin, roi_.rows + 2 * margin);
  }
  bool inRange(double v, const Scale& s) const {
    const double lo = std::min(s.lo, s.hi), hi = std::max(s.lo, s.hi);
    return v >= lo - 1e-9 * (hi - lo) && v <= hi + 1e-9 * (hi - lo);
  }

  void drawGrid() {
    for (const auto& t : p_.xt) {
      if (!inRange(t.value, p_.xs)) continue;
      const int x = static_cast<int>(std::lround(X(t.value)));
      cv::line(roi_, {x, 0}, {x, roi_.rows - 1}, t.major ? kGridMajor : kGridMinor, 1, cv::LINE_8);
    }
    for (const auto& t : p_.yt) {
      if (!inRange(t.value, p_.ys)) continue;
      const int y = static_cast<int>(std::lround(Y(t.value)));
      cv::line(roi_, {0, y}, {roi_.cols - 1, y}, t.major ? kGridMajor : kGridMinor, 1, cv::LINE_8);
    }
  }

  void drawSpans() {
    for (const auto& sp : ax_.spans) {
      if (!validOn(sp.x0, ax_.logx) || !validOn(sp.x1, ax_.logx)) continue;
      const double a = std::clamp(X(sp.x0), -4.0, roi_.cols + 4.0);
      const double b = std::clamp(X(sp.x1), -4.0, roi_.cols + 4.0);
      if (a == b) continue;
      std::vector<cv::Point2d> poly{{a, -4.0}, {b, -4.0}, {b, roi_.rows + 4.0}, {a, roi_.rows + 4.0}};
      std::vector<cv::Point> fp;
      for (const auto& q : poly) fp.push_back(fixedPt(q));
      blendFill(roi_, {fp}, bgr(sp.color), sp.alpha);
    }
  }

  void drawCells() {
    for (const auto& c : ax_.cells) {
      if (!validOn(c.x0, ax_.logx) || !validOn(c.x1, ax_.logx) || !validOn(c.y0, ax_.logy) ||
          !validOn(c.y1, ax_.logy))
        continue;
      const double xa = std::clamp(std::min(X(c.x0), X(c.x1)), -4.0, roi_.cols + 4.0);
      const double xb = std::clamp(std::max(X(c.x0), X(c.x1)), -4.0, roi_.cols + 4.0);
      const double ya = std::clamp(std::min(Y(c.y0), Y(c.y1)), -4.0, roi_.rows + 4.0);
      const double yb = std::clamp(std::max(Y(c.y0), Y(c.y1)), -4.0, roi_.rows + 4.0);
      if (xb - xa < 1.0 || yb - ya < 1.0) continue;
      // Pixel centres inside [xa, xb) x [ya, yb): adjacent cells tile exactly.
      const cv::Rect r = cv::Rect(cv::Point(static_cast<int>(std::ceil(xa - 0.5)), static_cast<int>(std::ceil(ya - 0.5))),
                                  cv::Point(static_cast<int>(std::ceil(xb - 0.5)), static_cast<int>(std::ceil(yb - 0.5)))) &
                         cv::Rect(0, 0, roi_.cols, roi_.rows);
      if (r.empty()) continue;
      roi_(r).setTo(bgr(c.fill));
      if (!occupancy_.empty()) occupancy_(r).setTo(cv::Scalar(40));
      if (c.outline > 0.0) {
        const int w = std::max(1, static_cast<int>(std::lround(c.outline)));
        for (int i = 0; i < w && 2 * i < std::min(r.width, r.height); ++i)
          cv::rectangle(roi_, cv::Point(r.x + i, r.y + i), cv::Point(r.x + r.width - 1 - i, r.y + r.height - 1 - i),
                        bgr(c.outline_color), 1, cv::LINE_8);
      }
      if (!c.text.empty()) {
        const int px = fitPx(tr_, c.text, sz_.tick, std::max(1, r.width - 4));
        cv::Mat full = canvas_;
        tr_.draw(full, c.text, {p_.area.x + r.x + r.width / 2, p_.area.y + r.y + r.height / 2}, px,
                 bgr(c.text_color), HAlign::Center, VAlign::Middle);
      }
    }
  }

  void drawBands() {
    const cv::Rect2d clip = clipRect(4);
    for (const auto& b : ax_.bands) {
      std::vector<std::vector<cv::Point>> polys;
      Run up, dn;
      auto flush = [&]() {
        if (up.size() >= 2) {
          // Dense data: keep the outer envelope per pixel column.
          if (up.size() > static_cast<std::size_t>(2 * roi_.cols)) {
            Run u2, d2;
            std::size_t i = 0;
            while (i < up.size()) {
              const double col = std::floor(up[i].x);
              double ymin = up[i].y, ymax = dn[i].y;
              std::size_t j = i;
              while (j < up.size() && std::floor(up[j].x) == col) {
                ymin = std::min(ymin, up[j].y);
                ymax = std::max(ymax, dn[j].y);
                ++j;
              }
              u2.push_back({up[i].x, ymin});
              d2.push_back({up[i].x, ymax});
              if (j - 1 != i) {
                u2.push_back({up[j - 1].x, ymin});
                d2.push_back({up[j - 1].x, ymax});
              }
              i = j;
            }
            up.swap(u2);
            dn.swap(d2);
          }
          std::vector<cv::Point2d> poly(up.begin(), up.end());
          poly.insert(poly.end(), dn.rbegin(), dn.rend());
          poly = clipPolygon(poly, clip);
          if (poly.size() >= 3) {
            std::vector<cv::Point> fp;
            fp.reserve(poly.size());
            for (const auto& q : poly) fp.push_back(fixedPt(q));
            polys.push_back(std::move(fp));
          }
        }
        up.clear();
        dn.clear();
      };
      const double below = roi_.rows + 1e4;  // non-positive lower bound on a log axis
      for (std::size_t i = 0; i < b.x.size(); ++i) {
        const bool ok = validOn(b.x[i], ax_.logx) && validOn(b.hi[i], ax_.logy) &&
                        std::isfinite(b.lo[i]);
        if (!ok) {
          flush();
          continue;
        }
        const double x = X(b.x[i]);
        const double yl = validOn(b.lo[i], ax_.logy) ? Y(b.lo[i]) : below;
        up.push_back({x, std::clamp(Y(b.hi[i]), -1e12, 1e12)});
        dn.push_back({x, std::clamp(yl, -1e12, 1e12)});
      }
      flush();
      blendFill(roi_, polys, bgr(b.color), b.alpha);
      if (!occupancy_.empty())
        for (const auto& poly : polys)
          cv::fillPoly(occupancy_, std::vector<std::vector<cv::Point>>{poly}, cv::Scalar(1),
                       cv::LINE_8, kShift);
    }
  }

  void drawHLines() {
    for (const auto& h : ax_.hlines) {
      if (!validOn(h.y, ax_.logy)) continue;
      const double y = Y(h.y);
      if (y < -4 || y > roi_.rows + 4) continue;
      const double w = std::max(1.0, 1.5 * sz_.s);
      const Run r{{0, y}, {roi_.cols - 1.0, y}};
      stroke(roi_, r, bgr(h.color), w, h.style == LineStyle::None ? LineStyle::Solid : h.style);
      if (!occupancy_.empty()) stroke(occupancy_, r, cv::Scalar(20), 3.0, LineStyle::Solid);
    }
  }

  void drawSeries() {
    for (const auto& s : ax_.series) {
      std::vector<Run> runs(1);
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        if (!validOn(s.x[i], ax_.logx) || !validOn(s.y[i], ax_.logy)) {
          if (!runs.back().empty()) runs.emplace_back();
          continue;
        }
        runs.back().push_back({X(s.x[i]), Y(s.y[i])});
      }
      const double margin = s.width + 4;
      if (s.style != LineStyle::None) {
        std::vector<Run> clipped = clipRuns(runs, clipRect(margin));
        for (auto& r : clipped) {
          Run d = decimate(r, roi_.cols);
          stroke(roi_, d, bgr(s.color), s.width, s.style);
          if (!occupancy_.empty()) stroke(occupancy_, d, cv::Scalar(40), std::max(s.width, 3.0), LineStyle::Solid);
        }
      }
      if (s.marker != Marker::None) {
        const cv::Rect2d box = clipRect(margin + 6);
        for (const auto& r : runs)
          for (const auto& q : r)
            if (box.contains(q)) {
              drawMarker(roi_, q, s.marker, bgr(s.color), s.width);
              if (!occupancy_.empty()) drawMarker(occupancy_, q, Marker::FilledCircle, cv::Scalar(40), s.width);
            }
      }
    }
  }

  void drawFrameAndTicks() {
    const cv::Rect& a = p_.area;
    cv::rectangle(canvas_, cv::Point(a.x - 1, a.y - 1), cv::Point(a.x + a.width, a.y + a.height), kInk,
                  1, cv::LINE_8);
    const int yb = a.y + a.height, xl = a.x - 1;
    for (const auto& t : p_.xt) {
      if (!inRange(t.value, p_.xs)) continue;
      const int x = static_cast<int>(std::lround(p_.xs.px(t.value)));
      cv::line(canvas_, {x, yb}, {x, yb + (t.major ? sz_.tickLen : sz_.minorLen)}, kInk, 1, cv::LINE_8);
      if (t.labeled)
        tr_.drawLabel(canvas_, t.label, {x, yb + sz_.tickLen + sz_.gap}, sz_.tick, kInk, HAlign::Center,
                      VAlign::Top);
    }
    for (const auto& t : p_.yt) {
      if (!inRange(t.value, p_.ys)) continue;
      const int y = static_cast<int>(std::lround(p_.ys.px(t.value)));
      cv::line(canvas_, {xl, y}, {xl - (t.major ? sz_.tickLen : sz_.minorLen), y}, kInk, 1, cv::LINE_8);
      if (t.labeled)
        tr_.drawLabel(canvas_, t.label, {xl - sz_.tickLen - sz_.gap, y}, sz_.tick, kInk, HAlign::Right,
                      VAlign::Middle);
    }
  }

  void drawLabels() {
    const cv::Rect& a = p_.area;
    const cv::Rect& c = p_.cell;
    if (!ax_.title.empty())
      tr_.draw(canvas_, ax_.title, {a.x + a.width / 2, a.y - 1 - sz_.labelGap},
               fitPx(tr_, ax_.title, sz_.title, c.width - sz_.pad), kInk, HAlign::Center, VAlign::Bottom);
    if (!ax_.xlabel.empty()) {
      int xh = 0;
      for (const auto& t : p_.xt)
        if (t.labeled) xh = std::max(xh, tr_.labelAscent(t.label, sz_.tick));
      const int y = a.y + a.height + sz_.tickLen + sz_.gap + xh + TextRenderer::descent(sz_.tick) + sz_.labelGap;
      tr_.draw(canvas_, ax_.xlabel, {a.x + a.width / 2, y}, fitPx(tr_, ax_.xlabel, sz_.label, c.width - sz_.pad),
               kInk, HAlign::Center, VAlign::Top);
    }
    if (!ax_.ylabel.empty()) {
      // At the left edge of the column's margin, so that the y labels of
      // stacked panels line up whatever their tick-label widths.
      const int x = c.x + sz_.pad;
      tr_.drawVertical(canvas_, ax_.ylabel, {x, a.y + a.height / 2},
                       fitPx(tr_, ax_.ylabel, sz_.label, a.height + a.height / 4), kInk);
    }
  }

  void drawLegend() {
    if (ax_.legend == LegendPos::None) return;
    const auto entries = legendEntries(ax_);
    if (entries.empty()) return;
    const int px = sz_.legend;
    const int rowH = static_cast<int>(std::lround(1.45 * px));
    const int sampleW = static_cast<int>(std::lround(2.3 * px));
    const int padX = static_cast<int>(std::lround(0.55 * px));
    const int padY = static_cast<int>(std::lround(0.35 * px));
    const int textGap = static_cast<int>(std::lround(0.5 * px));
    int textW = 0;
    for (const auto& e : entries) textW = std::max(textW, tr_.width(e.label, px));
    const int bw = padX + sampleW + textGap + textW + padX;
    const int bh = 2 * padY + rowH * static_cast<int>(entries.size());
    const int inset = static_cast<int>(std::lround(0.6 * px));
    const int W = roi_.cols, H = roi_.rows;
    auto at = [&](LegendPos pos) {
      switch (pos) {
        case LegendPos::TopLeft: return cv::Rect(inset, inset, bw, bh);
        case LegendPos::BottomLeft: return cv::Rect(inset, H - inset - bh, bw, bh);
        case LegendPos::BottomRight: return cv::Rect(W - inset - bw, H - inset - bh, bw, bh);
        default: return cv::Rect(W - inset - bw, inset, bw, bh);
      }
    };
    cv::Rect box = at(ax_.legend);
    if (ax_.legend == LegendPos::Best && !occupancy_.empty()) {
      // Candidates: corners, then edge centres; least covered data wins.
      std::vector<cv::Rect> cand{at(LegendPos::TopRight), at(LegendPos::TopLeft),
                                 at(LegendPos::BottomLeft), at(LegendPos::BottomRight),
                                 cv::Rect((W - bw) / 2, inset, bw, bh),
                                 cv::Rect((W - bw) / 2, H - inset - bh, bw, bh),
                                 cv::Rect(W - inset - bw, (H - bh) / 2, bw, bh),
                                 cv::Rect(inset, (H - bh) / 2, bw, bh)};
      double best = std::numeric_limits<double>::infinity();
      for (const auto& c : cand) {
        const cv::Rect r = c & cv::Rect(0, 0, W, H);
        if (r.empty()) continue;
        // Small penalty for the less conventional edge-centre positions.
        const double score = cv::sum(occupancy_(r))[0] + (&c - cand.data() >= 4 ? 200.0 : 0.0);
        if (score < best - 1e-9) {
          best = score;
          box = c;
        }
      }
    }
    // Semi-opaque background and a light frame.
    {
      const cv::Rect r = box & cv::Rect(0, 0, W, H);
      if (r.empty()) return;
      cv::Mat dst = roi_(r);
      cv::Mat white(dst.size(), dst.type(), cv::Scalar(255, 255, 255));
      cv::addWeighted(white, 0.85, dst, 0.15, 0.0, dst);
      cv::rectangle(roi_, box, cv::Scalar(200, 200, 200), 1, cv::LINE_8);
    }
    for (std::size_t i = 0; i < entries.size(); ++i) {
      const auto& e = entries[i];
      const double cy = box.y + padY + (i + 0.5) * rowH;
      const double x0 = box.x + padX, x1 = x0 + sampleW;
      if (e.kind == LegendEntry::Line) {
        stroke(roi_, Run{{x0, cy}, {x1, cy}}, bgr(e.color), e.width,
               e.style == LineStyle::None ? LineStyle::None : e.style);
        if (e.marker != Marker::None) drawMarker(roi_, {0.5 * (x0 + x1), cy}, e.marker, bgr(e.color), e.width);
      } else {
        const double hh = 0.36 * px;
        std::vector<cv::Point> fp{fixedPt({x0, cy - hh}), fixedPt({x1, cy - hh}), fixedPt({x1, cy + hh}),
                                  fixedPt({x0, cy + hh})};
        blendFill(roi_, {fp}, bgr(e.color), e.alpha);
      }
      cv::Mat full = canvas_;  // text may be clipped by the plot area only through the box
      tr_.draw(full, e.label,
               {p_.area.x + static_cast<int>(x1) + textGap, p_.area.y + static_cast<int>(std::lround(cy))},
               px, kInk, HAlign::Left, VAlign::Middle);
    }
  }

  cv::Mat& canvas_;
  const Panel& p_;
  const Axes& ax_;
  const Sizes& sz_;
  const TextRenderer& tr_;
  cv::Mat roi_;
  cv::Mat occupancy_;  // data pixels, for LegendPos::Best
};

cv::Mat render(const Figure& fig) {
  TextRenderer tr(fig.font);
  Layout L = computeLayout(fig, tr);
  cv::Mat canvas(fig.height, fig.width, CV_8UC3, cv::Scalar(255, 255, 255));
  for (const auto& p : L.panels) PanelPainter(canvas, p, L.sz, tr).draw();
  if (!fig.title.empty())
    tr.draw(canvas, fig.title, {fig.width / 2, L.sz.pad}, fitPx(tr, fig.title, L.sz.sup, fig.width - 2 * L.sz.pad),
            kInk, HAlign::Center, VAlign::Top);
  return canvas;
}

}  // namespace

std::vector<PixelRect> plotAreas(const Figure& fig) {
  TextRenderer tr(fig.font);
  const Layout L = computeLayout(fig, tr);
  std::vector<PixelRect> out;
  for (const auto& p : L.panels) out.push_back({p.area.x, p.area.y, p.area.width, p.area.height});
  return out;
}

void savePng(const Figure& fig, const std::string& path) {
  cv::Mat img;
  try {
    img = render(fig);
  } catch (const cv::Exception& e) {
    throw Error("plot: OpenCV failed while rendering '" + path + "': " + e.what());
  }
  std::vector<uchar> png;
  bool ok = false;
  try {
    ok = cv::imencode(".png", img, png);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) throw Error("plot: cannot encode PNG for '" + path + "'");
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error("plot: cannot open '" + path + "' for writing");
  out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  out.close();
  if (!out) throw Error("plot: cannot write PNG '" + path + "'");
}

}  // namespace navimpact::plot
