// plot_examples [outdir]: sample figures of the kinds navimpact produces, to be
// looked at by a person (not a test). Writes wv_loglog.png, nav_errors.png,
// nav_3x3.png, dense.png and edge_cases.png into outdir (default: current folder).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "navimpact/core/error.hpp"
#include "navimpact/plot/figure.hpp"

using namespace navimpact::plot;

namespace {

// Theoretical Haar wavelet variance of white noise (q2 = sigma^2 dt) plus
// random walk (gamma^2) plus a Gauss-Markov-like bump: enough to look real.
double wvModel(double tau, double wn, double rw, double gm) {
  return wn / tau + rw * tau / 12.0 + gm * tau * tau / (1.0 + tau * tau * 1e-4) * 1e-6;
}

Figure wvFigure() {
  std::mt19937 rng(42);
  std::normal_distribution<double> n01;
  Axes ax;
  ax.title = "Gyro x: Haar wavelet variance";
  ax.xlabel = "scale \xCF\x84 [s]";
  ax.ylabel = "wavelet variance \xCE\xBD\xC2\xB2 [(rad/s)\xC2\xB2]";
  ax.logx = ax.logy = true;
  Series emp{"empirical WV", {}, {}, palette(0), LineStyle::Solid, Marker::FilledCircle, 2.0};
  Band ci{"95% CI", {}, {}, {}, palette(0), 0.2};
  Series fit{"GMWM fit: WN + RW + GM", {}, {}, palette(1), LineStyle::Solid, Marker::None, 2.5};
  Series wn{"WN component", {}, {}, palette(2), LineStyle::Dashed, Marker::None, 2.0};
  Series rw{"RW component", {}, {}, palette(3), LineStyle::Dotted, Marker::None, 2.5};
  const double dt = 0.01;
  for (int j = 1; j <= 17; ++j) {
    const double tau = dt * std::pow(2.0, j);
    const double m = wvModel(tau, 1e-8, 4e-12, 3e-10);
    const double nEff = std::max(2.0, 360000.0 / std::pow(2.0, j));
    const double v = m * std::exp(n01(rng) * std::sqrt(2.0 / nEff));
    emp.x.push_back(tau);
    emp.y.push_back(v);
    ci.x.push_back(tau);
    ci.lo.push_back(v * std::exp(-1.96 * std::sqrt(2.0 / nEff)));
    ci.hi.push_back(v * std::exp(1.96 * std::sqrt(2.0 / nEff)));
  }
  for (int i = 0; i <= 200; ++i) {
    const double tau = std::pow(10.0, std::log10(0.02) + i * (std::log10(1400.0) - std::log10(0.02)) / 200);
    fit.x.push_back(tau);
    fit.y.push_back(wvModel(tau, 1e-8, 4e-12, 3e-10));
    wn.x.push_back(tau);
    wn.y.push_back(1e-8 / tau);
    rw.x.push_back(tau);
    rw.y.push_back(4e-12 * tau / 12.0);
  }
  ax.bands = {ci};
  ax.series = {emp, fit, wn, rw};
  Figure f;
  f.title = "Wavelet variance and GMWM model (synthetic example)";
  f.axes = {ax};
  return f;
}

Axes navPanel(const std::string& title, const std::string& ylabel, double sigma0, double grow,
              int seed, int color, bool withLegend) {
  std::mt19937 rng(static_cast<unsigned>(seed));
  std::normal_distribution<double> n01;
  Axes ax;
  ax.title = title;
  ax.xlabel = "time [s]";
  ax.ylabel = ylabel;
  Series err{"error", {}, {}, palette(color), LineStyle::Solid, Marker::None, 1.8};
  Band band{"\xC2\xB1" "1\xCF\x83 (filter)", {}, {}, {}, palette(color), 0.22};
  double e = 0;
  for (int i = 0; i <= 6000; ++i) {
    const double t = 0.1 * i;
    const bool out = t >= 300 && t <= 360;
    const double s = out ? sigma0 + grow * (t - 300) * (t - 300) : sigma0;
    e = 0.98 * e + 0.2 * s * n01(rng);
    err.x.push_back(t);
    err.y.push_back(e);
    band.x.push_back(t);
    band.lo.push_back(-s);
    band.hi.push_back(s);
  }
  if (!withLegend) {
    err.label.clear();
    band.label.clear();
  }
  ax.series = {err};
  ax.bands = {band};
  ax.spans = {Span{withLegend ? "GNSS outage" : "", 300, 360, {128, 128, 128}, 0.18}};
  ax.hlines = {HLine{"", 0.0, {90, 90, 90}, LineStyle::Dotted}};
  return ax;
}

Figure navFigure() {
  Figure f;
  f.title = "Navigation errors with a 60 s GNSS outage (synthetic)";
  f.rows = 3;
  f.cols = 1;
  f.axes = {navPanel("North position error", "\xCE\xB4p\xE2\x82\x99 [m]", 0.8, 0.004, 1, 0, true),
            navPanel("East position error", "\xCE\xB4p\xE2\x82\x91 [m]", 0.8, 0.003, 2, 1, false),
            navPanel("Down position error", "\xCE\xB4p_D [m]", 1.5, 0.001, 3, 2, false)};
  return f;
}

Figure nav3x3() {
  Figure f;
  f.title = "Navigation error, 3x3 panels";
  f.rows = f.cols = 3;
  const char* names[3][3] = {{"pos N", "pos E", "pos D"}, {"vel N", "vel E", "vel D"},
                             {"roll", "pitch", "yaw"}};
  const char* units[3] = {"[m]", "[m/s]", "[deg]"};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      const double s0 = r == 0 ? 0.8 : (r == 1 ? 0.05 : 0.02);
      Axes ax = navPanel(names[r][c], std::string("error ") + units[r], s0,
                         s0 * (r == 2 ? 1e-3 : 4e-3), 10 + 3 * r + c, c, r == 0 && c == 0);
      if (r < 2) ax.xlabel.clear();
      f.axes.push_back(ax);
    }
  return f;
}

Figure denseFigure() {
  Figure f;
  f.title = "Dense data: 3 series x 50,000 points";
  Axes ax;
  ax.title = "decimated per pixel column";
  ax.xlabel = "time [s]";
  ax.ylabel = "signal";
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  for (int k = 0; k < 3; ++k) {
    Series s;
    s.label = "series " + std::to_string(k);
    s.color = palette(k);
    s.width = 1.2;
    s.style = k == 2 ? LineStyle::Dashed : LineStyle::Solid;
    for (int i = 0; i < 50000; ++i) {
      s.x.push_back(i * 0.01);
      s.y.push_back(std::sin(i * 1e-3 * (k + 1)) + 0.05 * n01(rng) + 2.5 * k);
    }
    ax.series.push_back(s);
  }
  f.axes = {ax};
  return f;
}

Figure edgeCases() {
  // Small figure, 2x2: sub-decade log axis, large and tiny linear values,
  // markers of every kind, a log-log panel over 1.5 decades, NaN gaps.
  Figure f;
  f.width = 900;
  f.height = 600;
  f.rows = f.cols = 2;
  f.title = "Edge cases";
  Axes a;
  a.title = "log y over half a decade";
  a.logy = true;
  a.xlabel = "x";
  Series s{"y = 2 + x", {}, {}, palette(0), LineStyle::Solid, Marker::Circle, 1.5};
  for (int i = 0; i <= 10; ++i) {
    s.x.push_back(i * 0.3);
    s.y.push_back(2.0 + i * 0.3);
  }
  a.series = {s};
  Axes b;
  b.title = "large values, markers";
  b.ylabel = "counts";
  const Marker ms[4] = {Marker::Circle, Marker::FilledCircle, Marker::Square, Marker::Cross};
  for (int k = 0; k < 4; ++k) {
    Series m{"marker " + std::to_string(k), {}, {}, palette(k), k % 2 ? LineStyle::Dashed : LineStyle::None,
             ms[k], 1.5};
    for (int i = 0; i < 8; ++i) {
      m.x.push_back(1e6 + i * 2.5e5);
      m.y.push_back(123456.0 * (1 + k) + 20000.0 * i);
    }
    b.series.push_back(m);
  }
  Axes c;
  c.title = "tiny values with gaps";
  c.xlabel = "t [s]";
  c.ylabel = "bias [rad/s]";
  Series g{"", {}, {}, palette(4), LineStyle::Solid, Marker::None, 2};
  for (int i = 0; i <= 100; ++i) {
    g.x.push_back(i);
    g.y.push_back(i % 30 < 5 ? std::nan("") : 3e-5 * std::sin(i * 0.2));
  }
  c.series = {g};
  c.hlines = {HLine{"limit", 2.5e-5, {213, 94, 0}, LineStyle::Dashed}};
  Axes d;
  d.title = "log-log over 1.5 decades";
  d.logx = d.logy = true;
  Series p{"power law", {}, {}, palette(2), LineStyle::Solid, Marker::None, 2};
  for (int i = 0; i <= 50; ++i) {
    const double x = 0.05 * std::pow(30.0, i / 50.0);
    p.x.push_back(x);
    p.y.push_back(3.0 * std::sqrt(x));
  }
  d.series = {p};
  f.axes = {a, b, c, d};
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : ".";
  try {
    auto run = [&](const Figure& f, const std::string& name) {
      const auto t0 = std::chrono::steady_clock::now();
      savePng(f, dir + "/" + name);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      std::printf("%-16s %8.1f ms\n", name.c_str(), ms);
    };
    run(wvFigure(), "wv_loglog.png");
    run(navFigure(), "nav_errors.png");
    run(nav3x3(), "nav_3x3.png");
    run(denseFigure(), "dense.png");
    run(edgeCases(), "edge_cases.png");
  } catch (const navimpact::Error& e) {
    std::fprintf(stderr, "plot_examples: %s\n", e.what());
    return 1;
  }
  return 0;
}
