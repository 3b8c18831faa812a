// navimpact wv: empirical Haar wavelet variance (and Allan deviation) of an
// IMU recording, with the R gmwm package's 95 % CI.
//   navimpact wv --input FILE [--rate HZ] [--gyro-unit U] [--acc-unit U] [--axes SPEC]
//                [--label IMU] [--robust [--eff E]] [--allan] --out DIR
// Writes DIR/wv.json, DIR/wv.csv, DIR/wv_gyroscope.png, DIR/wv_accelerometer.png.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_common.hpp"
#include "input.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"
#include "navimpact/plot/figure.hpp"

namespace {

namespace gm = navimpact::gmwm;

struct Opts {
  navimpact::cli::InputOpts in;
  bool robust = false;
  double eff = 0.6;
  bool allan = false;
  std::string out;
  bool overwrite = false;
};

std::string squaredUnit(navimpact::units::Quantity q) {
  return q == navimpact::units::Quantity::AngularRate ? "(rad/s)^2" : "(m/s^2)^2";
}

std::vector<double> toStd(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

std::string g6(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

int run(const Opts& o) {
  navimpact::OutputSet outs(o.out, navimpact::cli::overwriteMode(o.overwrite));
  navimpact::cli::InputFormat fmt;
  const navimpact::ImuSeries s = navimpact::cli::loadInput(o.in, &fmt);
  gm::WvOptions wo;
  wo.robust = o.robust;
  wo.eff = o.eff;
  const std::vector<gm::WaveletVariance> wvs = gm::waveletVariances(s, wo);

  nlohmann::ordered_json j;
  j["input"] = {{"file", o.in.input},
                {"format", fmt == navimpact::cli::InputFormat::Rawlog ? "rawlog" : "csv"},
                {"rate_hz", s.rate_hz},
                {"samples", s.size()},
                {"units", navimpact::cli::inputUnitsNote(o.in, fmt)}};
  j["estimator"] = {
      {"wavelet", "Haar MODWT, scales 2^j samples, j = 1..floor(log2 N), boundary coefficients dropped"},
      {"type", o.robust ? "robust (Tukey biweight M-scale)" : "classical (mean of squares)"},
      {"ci", o.robust ? "95 % eta3 chi-square CI widened by 1/sqrt(eff)" : "95 % eta3 chi-square CI"},
      {"alpha", wo.alpha}};
  if (o.robust) j["estimator"]["eff"] = o.eff;
  std::ostringstream csv;
  csv << "channel,j,tau_s,wv,ci_low,ci_high\n";
  csv.precision(17);
  for (std::size_t c = 0; c < s.channels.size(); ++c) {
    const auto& ch = s.channels[c];
    const auto& w = wvs[c];
    nlohmann::ordered_json jc = {{"name", ch.name},
                         {"unit", squaredUnit(ch.quantity)},
                         {"tau_s", toStd(w.tauSeconds())},
                         {"wv", toStd(w.wv)},
                         {"ci_low", toStd(w.ci_low)},
                         {"ci_high", toStd(w.ci_high)}};
    if (o.allan) {
      // Cluster sizes m = 1, 2, 4, ... <= N/2 (IEEE Std 952 overlapping AVAR).
      std::vector<double> m;
      for (double v = 1; v <= static_cast<double>(s.size() / 2); v *= 2) m.push_back(v);
      const Eigen::VectorXd mv = Eigen::Map<const Eigen::VectorXd>(m.data(), m.size());
      const Eigen::VectorXd avar = gm::allanVariance(ch.x.data(), ch.x.size(), mv);
      std::vector<double> tau, adev;
      for (std::size_t k = 0; k < m.size(); ++k) {
        tau.push_back(m[k] / s.rate_hz);
        adev.push_back(std::sqrt(avar[k]));
      }
      jc["allan"] = {{"tau_s", tau},
                     {"adev", adev},
                     {"unit", navimpact::units::siUnit(ch.quantity)}};
    }
    j["channels"].push_back(jc);
    for (int i = 0; i < w.scales(); ++i)
      csv << ch.name << ',' << i + 1 << ',' << w.tau[i] / s.rate_hz << ',' << w.wv[i] << ','
          << w.ci_low[i] << ',' << w.ci_high[i] << '\n';
  }

  outs.writeText("wv.json", j.dump(2) + "\n");
  outs.writeText("wv.csv", csv.str());
  // One log-log figure per sensor: the axes present, each with its CI band.
  for (int sensor = 0; sensor < 2; ++sensor) {
    const auto q = sensor == 0 ? navimpact::units::Quantity::AngularRate
                               : navimpact::units::Quantity::SpecificForce;
    navimpact::plot::Axes ax;
    ax.logx = ax.logy = true;
    ax.xlabel = "scale τ [s]";
    ax.ylabel = std::string("wavelet variance ν² [") + squaredUnit(q) + "]";
    int k = 0;
    for (std::size_t c = 0; c < s.channels.size(); ++c) {
      if (s.channels[c].quantity != q) continue;
      const auto& w = wvs[c];
      const auto col = navimpact::plot::palette(k++);
      const auto tau = toStd(w.tauSeconds());
      ax.bands.push_back({"", tau, toStd(w.ci_low), toStd(w.ci_high), col, 0.2});
      ax.series.push_back({s.channels[c].name, tau, toStd(w.wv), col,
                           navimpact::plot::LineStyle::Solid, navimpact::plot::Marker::FilledCircle});
    }
    if (k == 0) continue;
    navimpact::plot::Figure fig;
    fig.title = std::string(sensor == 0 ? "Gyroscope" : "Accelerometer") + " Haar wavelet variance" +
                (o.robust ? " (robust)" : "") + " with 95 % CI";
    fig.axes = {ax};
    const std::string name = sensor == 0 ? "wv_gyroscope.png" : "wv_accelerometer.png";
    navimpact::plot::savePng(fig, outs.stage(name).string());
  }
  outs.commit();

  std::cout << "wavelet variance of " << o.in.input << ": " << s.size() << " samples at "
            << g6(s.rate_hz) << " Hz, " << (wvs.empty() ? 0 : wvs[0].scales()) << " scales"
            << (o.robust ? " (robust)" : "") << "\n";
  std::printf("  %-8s %-11s %-22s %-22s\n", "channel", "unit", "WV at smallest tau", "WV at largest tau");
  for (std::size_t c = 0; c < s.channels.size(); ++c) {
    const auto& w = wvs[c];
    const int J = w.scales() - 1;
    const std::string lo = g6(w.wv[0]) + " (" + g6(w.tau[0] / s.rate_hz) + " s)";
    const std::string hi = g6(w.wv[J]) + " (" + g6(w.tau[J] / s.rate_hz) + " s)";
    std::printf("  %-8s %-11s %-22s %-22s\n", s.channels[c].name.c_str(),
                squaredUnit(s.channels[c].quantity).c_str(), lo.c_str(), hi.c_str());
  }
  std::cout << "wrote";
  for (const auto& p : outs.finalPaths()) std::cout << " " << p.string();
  std::cout << "\n";
  return 0;
}

navimpact::cli::Registrar reg({"wv",
                               "Empirical Haar wavelet variance (and Allan deviation) of an IMU "
                               "recording, with 95 % confidence intervals",
                               [](CLI::App& app) {
                                 auto o = std::make_shared<Opts>();
                                 navimpact::cli::addInputOptions(app, o->in);
                                 app.add_flag("--robust", o->robust,
                                              "robust WV (Tukey biweight M-estimator of scale)");
                                 app.add_option("--eff", o->eff,
                                                "efficiency of the robust estimator, in (0, 1)")
                                     ->capture_default_str();
                                 app.add_flag("--allan", o->allan,
                                              "also write overlapping Allan deviations");
                                 app.add_option("--out", o->out, "output directory")->required();
                                 navimpact::cli::addOverwriteFlag(app, o->overwrite);
                                 return [o]() -> int { return run(*o); };
                               }});

}  // namespace
