// test_plot: render figures into a temporary folder, read the PNG back with
// OpenCV and check where the pixels landed (data-to-pixel mapping, bands,
// spans, log axes, legend, decimation) and the error paths.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>

#include "navimpact/core/error.hpp"
#include "navimpact/plot/figure.hpp"
#include "test_support.hpp"

namespace np = navimpact::plot;
namespace fs = std::filesystem;

namespace {

const np::Color kRed{255, 0, 0};

bool isRed(const cv::Vec3b& p) { return p[2] > 180 && p[1] < 90 && p[0] < 90; }
bool isWhite(const cv::Vec3b& p) { return p[0] == 255 && p[1] == 255 && p[2] == 255; }

/// A single 1x1 figure with fixed limits and nothing but what the test adds.
np::Figure bare(int w = 800, int h = 500) {
  np::Figure f;
  f.width = w;
  f.height = h;
  np::Axes ax;
  ax.grid = false;
  ax.legend = np::LegendPos::None;
  ax.xlim = std::make_pair(0.0, 1.0);
  ax.ylim = std::make_pair(0.0, 1.0);
  f.axes = {ax};
  return f;
}

np::Series line(std::vector<double> x, std::vector<double> y, np::Color c = kRed, double w = 2.0) {
  np::Series s;
  s.x = std::move(x);
  s.y = std::move(y);
  s.color = c;
  s.width = w;
  return s;
}

cv::Mat renderAndRead(const np::Figure& f, const std::string& name = "fig.png") {
  const fs::path p = navimpact::test::tempDir() / name;
  np::savePng(f, p.string());
  EXPECT_TRUE(fs::exists(p));
  cv::Mat img = cv::imread(p.string(), cv::IMREAD_COLOR);
  EXPECT_FALSE(img.empty()) << p;
  return img;
}

/// Mean position of the red pixels at positions lo..hi-1 of a column
/// (@p alongColumn, at x = @p at) or a row (at y = @p at); NaN if none.
double redMean(const cv::Mat& img, bool alongColumn, int at, int lo, int hi) {
  double sum = 0;
  int n = 0;
  for (int p = lo; p < hi; ++p)
    if (isRed(alongColumn ? img.at<cv::Vec3b>(p, at) : img.at<cv::Vec3b>(at, p))) {
      sum += p;
      ++n;
    }
  return n ? sum / n : std::numeric_limits<double>::quiet_NaN();
}

/// Mean row of red pixels in column @p x (NaN if none).
double redRowMean(const cv::Mat& img, int x, int y0, int y1) { return redMean(img, true, x, y0, y1); }

/// Mean column of red pixels in row @p y (NaN if none).
double redColMean(const cv::Mat& img, int y, int x0, int x1) { return redMean(img, false, y, x0, x1); }

}  // namespace

TEST(Plot, PaletteIsOkabeItoAndCycles) {
  const np::Color c0 = np::palette(0), c1 = np::palette(1), c8 = np::palette(8);
  EXPECT_EQ(c0.r, 0);
  EXPECT_EQ(c0.g, 114);
  EXPECT_EQ(c0.b, 178);
  EXPECT_EQ(c1.r, 213);
  EXPECT_EQ(c1.g, 94);
  EXPECT_EQ(c1.b, 0);
  EXPECT_EQ(c8.r, c0.r);
  EXPECT_EQ(c8.g, c0.g);
  EXPECT_EQ(c8.b, c0.b);
}

TEST(Plot, WritesPngOfRequestedSizeWithFrameAtReportedArea) {
  np::Figure f = bare(640, 420);
  f.axes[0].series = {line({0, 1}, {0.5, 0.5})};
  const cv::Mat img = renderAndRead(f);
  ASSERT_EQ(img.cols, 640);
  ASSERT_EQ(img.rows, 420);
  const auto areas = np::plotAreas(f);
  ASSERT_EQ(areas.size(), 1u);
  const auto a = areas[0];
  EXPECT_GT(a.x, 10);
  EXPECT_GT(a.width, 300);
  EXPECT_LT(a.x + a.width, 640);
  EXPECT_LT(a.y + a.height, 420);
  // Frame just outside the area, blank just inside (grid off, no data there).
  const int ym = a.y + a.height / 4;
  EXPECT_LT(img.at<cv::Vec3b>(ym, a.x - 1)[0], 100);
  EXPECT_LT(img.at<cv::Vec3b>(ym, a.x + a.width)[0], 100);
  EXPECT_TRUE(isWhite(img.at<cv::Vec3b>(ym, a.x + 2)));
  const int xm = a.x + a.width / 3;
  EXPECT_LT(img.at<cv::Vec3b>(a.y - 1, xm)[0], 100);
  EXPECT_LT(img.at<cv::Vec3b>(a.y + a.height, xm)[0], 100);
}

TEST(Plot, HorizontalLinesLandAtTheirYValue) {
  np::Figure f = bare();
  f.axes[0].series = {line({0, 1}, {0.5, 0.5}), line({0, 1}, {0.25, 0.25})};
  const cv::Mat img = renderAndRead(f);
  const auto a = np::plotAreas(f)[0];
  const int x = a.x + a.width / 2;
  // Rows of red in the upper and lower half of the plot area separately.
  const double rHalf = redRowMean(img, x, a.y, a.y + a.height * 5 / 8);
  const double rQuarter = redRowMean(img, x, a.y + a.height * 5 / 8, a.y + a.height);
  EXPECT_NEAR(rHalf, a.y + 0.5 * a.height, 2.0);
  EXPECT_NEAR(rQuarter, a.y + 0.75 * a.height, 2.0);  // y grows upwards
  // Nothing red in the top quarter.
  EXPECT_TRUE(std::isnan(redRowMean(img, x, a.y, a.y + a.height / 4)));
}

TEST(Plot, VerticalLineLandsAtItsXValue) {
  np::Figure f = bare();
  f.axes[0].series = {line({0.8, 0.8}, {0, 1})};
  const cv::Mat img = renderAndRead(f);
  const auto a = np::plotAreas(f)[0];
  const double c = redColMean(img, a.y + a.height / 2, a.x, a.x + a.width);
  EXPECT_NEAR(c, a.x + 0.8 * a.width, 2.0);
}

TEST(Plot, LogAxesPlaceDecadesEquallySpaced) {
  np::Figure f = bare();
  f.axes[0].logx = true;
  f.axes[0].logy = true;
  f.axes[0].xlim = std::make_pair(1e-3, 1e-1);
  f.axes[0].ylim = std::make_pair(1e-3, 1e-1);
  f.axes[0].series = {line({1e-3, 1e-1}, {1e-2, 1e-2}), line({1e-2, 1e-2}, {1e-3, 1e-1})};
  const cv::Mat img = renderAndRead(f);
  const auto a = np::plotAreas(f)[0];
  // 1e-2 is midway in log10 (a linear axis would put it 9% from the low end).
  const double row = redRowMean(img, a.x + a.width / 4, a.y, a.y + a.height);
  const double col = redColMean(img, a.y + a.height / 4, a.x, a.x + a.width);
  EXPECT_NEAR(row, a.y + 0.5 * a.height, 2.0);
  EXPECT_NEAR(col, a.x + 0.5 * a.width, 2.0);
}

TEST(Plot, LogAxisIgnoresNonPositiveValuesInAutoLimits) {
  np::Figure f = bare();
  f.axes[0].ylim.reset();
  f.axes[0].logy = true;
  // y = 1e-3 .. 1e-1 plus non-positive values which must be skipped.
  f.axes[0].series = {line({0, 0.2, 0.4, 0.6, 1.0}, {-5.0, 1e-3, 0.0, 1e-1, 1e-2})};
  const cv::Mat img = renderAndRead(f);
  const auto a = np::plotAreas(f)[0];
  // Auto limits: [1e-3, 1e-1] padded by 5 % of the 2 decades at each end,
  // i.e. log10 limits [-3.1, -0.9]. The segment 0.6 -> 1.0 runs from 1e-1 to
  // 1e-2, so at x = 0.8 it is at log10 y = -1.5: (1.5 - 0.9) / 2.2 below the top.
  const double row = redRowMean(img, a.x + static_cast<int>(0.8 * a.width), a.y, a.y + a.height);
  EXPECT_NEAR(row, a.y + 0.6 / 2.2 * a.height, 3.0);
}

TEST(Plot, LogAxisWithOnlyNonPositiveDataIsAnError) {
  np::Figure f = bare();
  f.axes[0].ylim.reset();
  f.axes[0].logy = true;
  f.axes[0].series = {line({0, 1}, {-1.0, 0.0})};
  EXPECT_THROW(np::savePng(f, (navimpact::test::tempDir() / "x.png").string()), navimpact::Error);
}

TEST(Plot, BandShadesBetweenLoAndHiOnly) {
  np::Figure f = bare();
  np::Band b;
  b.x = {0.0, 1.0};
  b.lo = {0.4, 0.4};
  b.hi = {0.6, 0.6};
  b.color = {0, 0, 255};
  b.alpha = 0.3;
  f.axes[0].bands = {b};
  const cv::Mat img = renderAndRead(f);
  const auto a = np::plotAreas(f)[0];
  const int x = a.x + a.width / 2;
  auto rowOf = [&](double y) { return static_cast<int>(std::lround(a.y + (1.0 - y) * a.height)); };
  const cv::Vec3b in = img.at<cv::Vec3b>(rowOf(0.5), x);
  EXPECT_GT(in[0], 240);                // blue channel kept
  EXPECT_NEAR(in[2], 255 * 0.7, 3.0);   // red reduced by alpha
  EXPECT_NEAR(in[1], 255 * 0.7, 3.0);
  EXPECT_FALSE(isWhite(img.at<cv::Vec3b>(rowOf(0.43), x)));
  EXPECT_TRUE(isWhite(img.at<cv::Vec3b>(rowOf(0.35), x)));
  EXPECT_TRUE(isWhite(img.at<cv::Vec3b>(rowOf(0.65), x)));
  EXPECT_TRUE(isWhite(img.at<cv::Vec3b>(rowOf(0.2), x)));
}

TEST(Plot, SpanShadesItsXRangeOverTheFullHeight) {
  np::Figure f = bare();
  f.axes[0].spans = {np::Span{"outage", 0.2, 0.4, {0, 0, 0}, 0.2}};
  const cv::Mat img = renderAndRead(f);
  const auto a = np::plotAreas(f)[0];
  auto colOf = [&](double x) { return static_cast<int>(std::lround(a.x + x * a.width)); };
  for (int y : {a.y + 3, a.y + a.height / 2, a.y + a.height - 4}) {
    EXPECT_NEAR(img.at<cv::Vec3b>(y, colOf(0.3))[0], 255 * 0.8, 3.0) << y;
    EXPECT_NEAR(img.at<cv::Vec3b>(y, colOf(0.22))[0], 255 * 0.8, 3.0) << y;
    EXPECT_TRUE(isWhite(img.at<cv::Vec3b>(y, colOf(0.18)))) << y;
    EXPECT_TRUE(isWhite(img.at<cv::Vec3b>(y, colOf(0.42)))) << y;
    EXPECT_TRUE(isWhite(img.at<cv::Vec3b>(y, colOf(0.7)))) << y;
  }
}

TEST(Plot, NonFinitePointsBreakTheLine) {
  np::Figure f = bare();
  std::vector<double> x, y;
  for (int i = 0; i <= 100; ++i) {
    x.push_back(i / 100.0);
    y.push_back(i >= 40 && i <= 60 ? std::numeric_limits<double>::quiet_NaN() : 0.5);
  }
  f.axes[0].series = {line(x, y)};
  const cv::Mat img = renderAndRead(f);
  const auto a = np::plotAreas(f)[0];
  auto colOf = [&](double v) { return static_cast<int>(std::lround(a.x + v * a.width)); };
  EXPECT_FALSE(std::isnan(redRowMean(img, colOf(0.3), a.y, a.y + a.height)));
  EXPECT_TRUE(std::isnan(redRowMean(img, colOf(0.5), a.y, a.y + a.height)));
  EXPECT_FALSE(std::isnan(redRowMean(img, colOf(0.7), a.y, a.y + a.height)));
}

TEST(Plot, DashedLineHasGapsSolidLineHasNone) {
  auto coverage = [](np::LineStyle st) {
    np::Figure f = bare();
    np::Series s = line({0, 1}, {0.5, 0.5});
    s.style = st;
    f.axes[0].series = {s};
    const cv::Mat img = renderAndRead(f);
    const auto a = np::plotAreas(f)[0];
    const int row = static_cast<int>(std::lround(a.y + 0.5 * a.height - 0.5));
    int on = 0, n = 0, transitions = 0;
    bool prev = false;
    for (int x = a.x + 10; x < a.x + a.width - 10; ++x, ++n) {
      bool r = false;
      for (int dy = -1; dy <= 1; ++dy) r = r || isRed(img.at<cv::Vec3b>(row + dy, x));
      on += r;
      if (x > a.x + 10 && r != prev) ++transitions;
      prev = r;
    }
    return std::make_pair(double(on) / n, transitions);
  };
  const auto solid = coverage(np::LineStyle::Solid);
  const auto dashed = coverage(np::LineStyle::Dashed);
  const auto dotted = coverage(np::LineStyle::Dotted);
  EXPECT_GT(solid.first, 0.99);
  EXPECT_EQ(solid.second, 0);
  EXPECT_GT(dashed.first, 0.4);
  EXPECT_LT(dashed.first, 0.9);
  EXPECT_GT(dashed.second, 40);
  EXPECT_LT(dotted.first, dashed.first);
  EXPECT_GT(dotted.second, dashed.second);
}

TEST(Plot, DenseSeriesKeepsIsolatedExtremes) {
  // 50,000 points, one single-sample spike: per-column decimation must keep it.
  np::Figure f = bare();
  std::vector<double> x(50000), y(50000, 0.1);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = double(i) / (x.size() - 1);
  y[31234] = 0.9;
  f.axes[0].series = {line(x, y, kRed, 1.0)};
  const cv::Mat img = renderAndRead(f);
  const auto a = np::plotAreas(f)[0];
  const int rowSpike = static_cast<int>(std::lround(a.y + 0.1 * a.height));
  const double c = redColMean(img, rowSpike, a.x, a.x + a.width);
  EXPECT_NEAR(c, a.x + x[31234] * a.width, 3.0);
}

TEST(Plot, LegendDrawsTextAndSamplesInItsCorner) {
  auto darkInTopRight = [](const std::string& label) {
    np::Figure f = bare();
    f.axes[0].legend = np::LegendPos::TopRight;
    np::Series s = line({0, 1}, {0.1, 0.1});
    s.label = label;
    f.axes[0].series = {s};
    const cv::Mat img = renderAndRead(f, label.empty() ? "none.png" : "legend.png");
    const auto a = np::plotAreas(f)[0];
    int dark = 0, red = 0;
    for (int y = a.y; y < a.y + a.height / 3; ++y)
      for (int x = a.x + a.width / 2; x < a.x + a.width; ++x) {
        const auto p = img.at<cv::Vec3b>(y, x);
        dark += p[0] < 100 && p[1] < 100 && p[2] < 100;
        red += isRed(p);
      }
    return std::make_pair(dark, red);
  };
  const auto with = darkInTopRight("reference trajectory");
  const auto without = darkInTopRight("");
  EXPECT_GT(with.first, 50);   // glyph pixels
  EXPECT_GT(with.second, 10);  // red line sample
  EXPECT_EQ(without.first, 0);
  EXPECT_EQ(without.second, 0);
}

TEST(Plot, BestLegendAvoidsTheData) {
  np::Figure f = bare();
  f.axes[0].legend = np::LegendPos::Best;
  // A zigzag filling the whole top half: the legend must go to the bottom half.
  std::vector<double> x, y;
  for (int i = 0; i <= 200; ++i) {
    x.push_back(i / 200.0);
    y.push_back(i % 2 ? 0.99 : 0.52);
  }
  np::Series s = line(x, y);
  s.label = "data";
  f.axes[0].series = {s};
  const cv::Mat img = renderAndRead(f);
  const auto a = np::plotAreas(f)[0];
  auto darkIn = [&](int y0, int y1) {
    int dark = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = a.x + 2; x < a.x + a.width - 2; ++x) {
        const auto p = img.at<cv::Vec3b>(y, x);
        dark += p[0] < 100 && p[1] < 100 && p[2] < 100;
      }
    return dark;
  };
  EXPECT_EQ(darkIn(a.y + 2, a.y + a.height / 2), 0);
  EXPECT_GT(darkIn(a.y + a.height / 2, a.y + a.height - 2), 50);
}

TEST(Plot, GridOfPanelsIsRowMajorAndAligned) {
  np::Figure f;
  f.rows = 2;
  f.cols = 2;
  f.title = "grid";
  for (int i = 0; i < 4; ++i) {
    np::Axes ax;
    ax.title = "panel " + std::to_string(i);
    ax.ylabel = "value";
    ax.series = {line({0, 1}, {0, i == 3 ? 12345.0 : 1.0})};
    f.axes.push_back(ax);
  }
  const auto r = np::plotAreas(f);
  ASSERT_EQ(r.size(), 4u);
  EXPECT_EQ(r[0].x, r[2].x);
  EXPECT_EQ(r[1].x, r[3].x);
  EXPECT_EQ(r[0].y, r[1].y);
  EXPECT_EQ(r[2].y, r[3].y);
  EXPECT_GT(r[1].x, r[0].x + r[0].width);
  EXPECT_GT(r[2].y, r[0].y + r[0].height);
  EXPECT_LE(r[3].x + r[3].width, f.width);
  EXPECT_LE(r[3].y + r[3].height, f.height);
  const cv::Mat img = renderAndRead(f);
  EXPECT_EQ(img.cols, f.width);
}

TEST(Plot, DegenerateDataStillRenders) {
  // Each panel holds data that commonly breaks naive plotting code; all must
  // render (and the constant series must land on the middle row).
  np::Figure f;
  f.rows = 2;
  f.cols = 3;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  np::Axes constant, single, allNan, huge, tinyRange, farOut;
  constant.series = {line({0, 1, 2}, {3.0, 3.0, 3.0})};
  single.series = {line({1.0}, {2.0})};
  single.series[0].marker = np::Marker::Square;
  allNan.series = {line({nan, nan}, {nan, inf})};
  huge.series = {line({1e20, 1e20 + 5e5}, {-1e300, 1e300})};
  tinyRange.series = {line({0, 1}, {1.0, 1.0 + 1e-13})};
  farOut.ylim = std::make_pair(0.0, 1.0);
  farOut.series = {line({0, 0.5, 1}, {0.5, 1e15, 0.5})};
  farOut.bands = {np::Band{"", {0, 1}, {-1e200, -1e200}, {1e200, 1e200}, {0, 0, 255}, 0.2}};
  f.axes = {constant, single, allNan, huge, tinyRange, farOut};
  const cv::Mat img = renderAndRead(f);
  const auto a = np::plotAreas(f)[0];
  EXPECT_NEAR(redRowMean(img, a.x + a.width / 2, a.y, a.y + a.height), a.y + 0.5 * a.height, 2.0);
}

TEST(Plot, MissingFontIsAnErrorNamingThePath) {
  np::Figure f = bare();
  f.font = "/nonexistent/dir/NoSuchFont.ttf";
  const fs::path out = navimpact::test::tempDir() / "nofont.png";
  try {
    np::savePng(f, out.string());
    FAIL() << "expected navimpact::Error";
  } catch (const navimpact::Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/NoSuchFont.ttf"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(out));
}

TEST(Plot, EmptyFigureAndBadGridAreErrors) {
  np::Figure empty;
  const fs::path out = navimpact::test::tempDir() / "e.png";
  EXPECT_THROW(np::savePng(empty, out.string()), navimpact::Error);
  np::Figure tooMany = bare();
  tooMany.axes.push_back(tooMany.axes[0]);
  EXPECT_THROW(np::savePng(tooMany, out.string()), navimpact::Error);
  np::Figure badLim = bare();
  badLim.axes[0].xlim = std::make_pair(1.0, 1.0);
  EXPECT_THROW(np::savePng(badLim, out.string()), navimpact::Error);
  EXPECT_FALSE(fs::exists(out));
}

TEST(Plot, UnwritablePathIsAnErrorNamingThePath) {
  np::Figure f = bare();
  const std::string bad = (navimpact::test::tempDir() / "no_such_dir" / "f.png").string();
  try {
    np::savePng(f, bad);
    FAIL() << "expected navimpact::Error";
  } catch (const navimpact::Error& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
}

TEST(Plot, HeatMapCellsTileTheirDataRectanglesWithTextOutlineAndCategoricalTicks) {
  // 3 x 2 cells over [0, 3] x [0, 2]: cell (i, j) spans x in [i, i+1], y in [j, j+1].
  np::Figure f = bare(700, 460);
  np::Axes& ax = f.axes[0];
  ax.xlim = std::make_pair(0.0, 3.0);
  ax.ylim = std::make_pair(0.0, 2.0);
  const np::Color fills[2] = {{0, 114, 178}, {230, 159, 0}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) {
      np::Cell c;
      c.x0 = i;
      c.x1 = i + 1;
      c.y0 = j;
      c.y1 = j + 1;
      c.fill = fills[(i + j) % 2];
      if (i == 1 && j == 0) {
        c.text = "1.23";
        c.text_color = {255, 255, 255};
      }
      if (i == 2 && j == 1) {
        c.outline = 4;
        c.outline_color = {0, 0, 0};
      }
      ax.cells.push_back(c);
    }
  ax.xticks = {{0.5, "5 s"}, {1.5, "10 s"}, {2.5, "60 s"}};
  ax.yticks = {{0.5, "WN"}, {1.5, "Ref"}};
  const cv::Mat img = renderAndRead(f, "heat.png");
  const auto a = np::plotAreas(f)[0];
  auto px = [&](double x, double y) {
    const int c = a.x + static_cast<int>(std::lround(x / 3.0 * a.width - 0.5));
    const int r = a.y + static_cast<int>(std::lround((1.0 - y / 2.0) * a.height - 0.5));
    return img.at<cv::Vec3b>(r, c);
  };
  auto same = [](const cv::Vec3b& p, np::Color c) { return p[2] == c.r && p[1] == c.g && p[0] == c.b; };
  // Fill at a quarter of each cell (away from text), corners of neighbours exact.
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j)
      EXPECT_TRUE(same(px(i + 0.2, j + 0.2), fills[(i + j) % 2])) << "cell " << i << "," << j;
  // No white gap between adjacent cells along a shared edge.
  const int yr = a.y + a.height / 4;
  for (int x = a.x + 2; x < a.x + a.width - 2; ++x) EXPECT_FALSE(isWhite(img.at<cv::Vec3b>(yr, x))) << x;
  // Text: light pixels near the centre of cell (1, 0) only.
  auto lightAround = [&](double x, double y) {
    int n = 0;
    for (double dx = -0.3; dx <= 0.3; dx += 0.005)
      for (double dy = -0.1; dy <= 0.1; dy += 0.005) n += px(x + dx, y + dy)[0] > 150 ? 1 : 0;
    return n;
  };
  EXPECT_GT(lightAround(1.5, 0.5), 20);
  EXPECT_EQ(lightAround(0.5, 1.5), 0);  // an orange cell without text
  // Outline: black at the inner edge of cell (2, 1), its fill further inside.
  const int cx = a.x + static_cast<int>(std::lround(2.5 / 3.0 * a.width));
  EXPECT_LT(img.at<cv::Vec3b>(a.y + 1, cx)[0], 40);
  EXPECT_TRUE(same(img.at<cv::Vec3b>(a.y + 8, cx), fills[1]));
  // Categorical tick labels: ink below the frame under each tick, none between.
  auto inkBelow = [&](int x) {
    int n = 0;
    for (int y = a.y + a.height + 8; y < std::min(img.rows, a.y + a.height + 40); ++y)
      for (int dx = -12; dx <= 12; ++dx) n += img.at<cv::Vec3b>(y, x + dx)[0] < 120 ? 1 : 0;
    return n;
  };
  EXPECT_GT(inkBelow(a.x + a.width / 6), 5);
  EXPECT_GT(inkBelow(a.x + a.width * 5 / 6), 5);
  EXPECT_EQ(inkBelow(a.x + a.width / 3), 0);
}
