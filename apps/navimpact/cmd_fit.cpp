// navimpact fit: GMWM fit of an IMU error model to a static recording.
//   navimpact fit --input FILE [--rate HZ] [--gyro-unit U] [--acc-unit U] [--axes SPEC]
//                 [--label L] [--channels gyro_x,...] --structure SPEC|auto
//                 [--max-gm N] [--bootstrap N] [--intervals profile|asymptotic]
//                 [--weights r|model|efficient] [--seed S] --out DIR
// Writes DIR/model.yaml (stochastic::loadImuModel reads it back), DIR/fit.json
// (estimates, intervals, WV and model WV per channel) and one WV figure per
// sensor (fit_gyroscope.png, fit_accelerometer.png), all or nothing.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli_common.hpp"
#include "input.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/imu_series.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/gmwm/estimator.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"
#include "navimpact/plot/figure.hpp"
#include "navimpact/stochastic/datasheet.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

namespace {

namespace st = navimpact::stochastic;
namespace gm = navimpact::gmwm;
using json = nlohmann::json;

struct Opts {
  navimpact::cli::InputOpts in;  // --input --rate --gyro-unit --acc-unit --axes --label (input.hpp)
  std::string channels;
  std::string structure;
  int max_gm = 3;
  int bootstrap = 0;
  std::string intervals = "profile";
  std::string weights = "r";
  std::uint64_t seed = 20190101;
  std::string out;
  bool overwrite = false;
};

struct ChannelFit {
  const navimpact::ImuChannel* ch = nullptr;
  gm::WaveletVariance wv;
  gm::FitResult fit;
  std::vector<gm::RankedModel> ranking;  // auto only
  std::string why;
};

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string t;
  while (std::getline(ss, t, ','))
    if (!t.empty()) out.push_back(t);
  return out;
}

std::vector<double> vec(const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

json termJson(const st::Process& p, const std::vector<gm::ParamInterval>& ci) {
  json t;
  t["process"] = st::kindName(p.kind);
  json c = json::object();
  for (const auto& pi : ci) {
    t[pi.name] = pi.value;
    c[pi.name] = {{"low", pi.low}, {"high", pi.high}};
  }
  t["ci"] = c;
  return t;
}

json datasheetJson(const st::DatasheetFigures& f) {
  json d = json::object();
  auto put = [&](const char* k, const std::optional<double>& v) {
    if (v) d[k] = *v;
  };
  put("noise_density", f.noise_density);
  put("bias_instability", f.bias_instability);
  put("bias_instability_tau_s", f.bias_instability_tau_s);
  put("random_walk", f.random_walk);
  put("quantization", f.quantization);
  put("drift_rate", f.drift_rate);
  return d;
}

/// One WV panel in the style of the paper's Figures 1-4.
navimpact::plot::Axes wvAxes(const ChannelFit& c) {
  namespace pl = navimpact::plot;
  pl::Axes ax;
  ax.logx = ax.logy = true;
  ax.title = c.ch->name + ": " + st::formatStructure([&] {
    std::vector<st::ProcessKind> k;
    for (const auto& t : c.fit.model.terms) k.push_back(t.kind);
    return k;
  }());
  const std::string u = navimpact::units::siUnit(c.ch->quantity);
  ax.xlabel = "scale τ [s]";
  ax.ylabel = "wavelet variance [(" + u + ")²]";
  const auto tau_s = vec(c.wv.tauSeconds());
  ax.bands.push_back({"95% CI", tau_s, vec(c.wv.ci_low), vec(c.wv.ci_high), pl::palette(0), 0.2});
  ax.series.push_back({"empirical WV", tau_s, vec(c.wv.wv), pl::palette(0), pl::LineStyle::Solid,
                       pl::Marker::FilledCircle, 2.0});
  const Eigen::MatrixXd terms = st::haarWvTerms(c.fit.model, c.wv.tau);
  const std::vector<bool> neg = gm::negligibleTerms(c.fit.model, c.wv);
  for (Eigen::Index i = 0; i < terms.cols(); ++i) {
    const auto& p = c.fit.model.terms[static_cast<std::size_t>(i)];
    std::string lab = st::kindName(p.kind);
    if (p.kind == st::ProcessKind::GM) {
      char b[48];
      std::snprintf(b, sizeof b, "GM (T = %.3g s)", p.T);
      lab = b;
    }
    if (neg[static_cast<std::size_t>(i)]) lab += " (negligible)";
    ax.series.push_back({lab, tau_s, vec(terms.col(i)), pl::palette(static_cast<int>(i) + 2),
                         pl::LineStyle::Dashed, pl::Marker::None, 1.5});
  }
  ax.series.push_back({"model WV", tau_s, vec(st::haarWv(c.fit.model, c.wv.tau)), pl::palette(1),
                       pl::LineStyle::Solid, pl::Marker::Circle, 2.0});
  // Components far below the data would stretch the log axis: limit y to the data range.
  const double lo = c.wv.ci_low.minCoeff() > 0 ? c.wv.ci_low.minCoeff() : c.wv.wv.minCoeff();
  ax.ylim = std::make_pair(lo / 10.0, c.wv.ci_high.maxCoeff() * 3.0);
  return ax;
}

int run(const Opts& o) {
  // Structure (parsed first: a bad spec fails before reading a large file).
  const bool autoSel = o.structure == "auto";
  std::vector<st::ProcessKind> structure;
  if (!autoSel) structure = st::parseStructure(o.structure);
  navimpact::OutputSet outs(o.out, navimpact::cli::overwriteMode(o.overwrite));
  if (o.bootstrap < 0) throw navimpact::Error("--bootstrap must be >= 0, got " + std::to_string(o.bootstrap));
  if (o.max_gm < 0 || o.max_gm > 3) throw navimpact::Error("--max-gm must be in 0..3");
  if (o.weights != "r" && o.weights != "model" && o.weights != "efficient")
    throw navimpact::Error("--weights: expected 'r', 'model' or 'efficient', got '" + o.weights + "'");

  navimpact::cli::InputFormat fmt{};
  const navimpact::ImuSeries s = navimpact::cli::loadInput(o.in, &fmt);
  const std::string& input = o.in.input;

  std::vector<const navimpact::ImuChannel*> chans;
  if (o.channels.empty()) {
    for (const auto& c : s.channels) chans.push_back(&c);
  } else {
    for (const auto& n : splitList(o.channels)) {
      if (navimpact::channelIndex(n) < 0)
        throw navimpact::Error("--channels: unknown channel '" + n +
                               "' (expected gyro_x, gyro_y, gyro_z, acc_x, acc_y, acc_z)");
      chans.push_back(&s.channel(n));
    }
  }
  if (chans.empty()) throw navimpact::Error(input + ": no IMU channel to fit");

  gm::FitOptions fo;
  fo.bootstrap = o.bootstrap;
  if (o.intervals == "profile")
    fo.intervals = gm::IntervalMethod::Profile;
  else if (o.intervals == "asymptotic")
    fo.intervals = gm::IntervalMethod::Asymptotic;
  else
    throw navimpact::Error("--intervals: expected 'profile' or 'asymptotic', got '" + o.intervals + "'");
  fo.seed = o.seed;
  // r: the R package's objective (weights 1/(CI_hi - CI_lo)^2); model: iterated
  // model-based diagonal weights; efficient: inverse of the full WV covariance.
  if (o.weights == "r")
    fo.weighting = gm::Weighting::Fast;
  else if (o.weights == "model")
    fo.weighting = gm::Weighting::ModelBased;
  else if (o.weights == "efficient")
    fo.weighting = gm::Weighting::Efficient;
  else
    throw navimpact::Error("--weights: expected 'r', 'model' or 'efficient', got '" + o.weights + "'");
  const auto cands = gm::defaultCandidates(o.max_gm);

  std::vector<ChannelFit> fits(chans.size());
  navimpact::cli::Progress prog("fit", chans.size());
  for (std::size_t i = 0; i < chans.size(); ++i) {
    ChannelFit& c = fits[i];
    c.ch = chans[i];
    c.wv = gm::waveletVariance(c.ch->x.data(), c.ch->x.size(), s.rate_hz);
    gm::FitOptions fi = fo;
    fi.seed = st::deriveSeed(o.seed, static_cast<std::uint64_t>(navimpact::channelIndex(c.ch->name)));
    try {
      if (autoSel) {
        // The WIC's optimism is derived for R's weights: rank with them, then
        // refit the pick with the requested weights.
        gm::FitOptions fr = fi;
        fr.weighting = gm::Weighting::Fast;
        c.ranking = gm::selectModel(cands, c.wv, fr, &c.why);
        c.fit = c.ranking.front().fit;
        if (fi.weighting != gm::Weighting::Fast) {
          std::vector<st::ProcessKind> k;
          for (const auto& t : c.fit.model.terms) k.push_back(t.kind);
          fi.warm_starts = {c.fit.model};
          c.fit = gm::fit(k, c.wv, fi);
          c.why += "; ranked with the R weights, the pick refit with --weights " + o.weights;
        }
      } else {
        c.fit = gm::fit(structure, c.wv, fi);
      }
    } catch (const navimpact::Error& e) {
      throw navimpact::Error(input + ": channel " + c.ch->name + ": " + e.what());
    }
    prog.update(i + 1);
  }
  prog.finish();

  // model.yaml: per-axis keys at the data rate; channels not fitted stay "none".
  st::ImuModel im;
  im.rate_hz = s.rate_hz;
  for (auto& m : im.axis) m.rate_hz = s.rate_hz;
  for (const auto& c : fits) im.forChannel(c.ch->name) = c.fit.model;

  json j;
  j["input"] = {{"file", input},
                {"format", fmt == navimpact::cli::InputFormat::Rawlog ? "rawlog" : "csv"},
                {"rate_hz", s.rate_hz},
                {"samples", s.size()},
                {"units", navimpact::cli::inputUnitsNote(o.in, fmt)},
                {"axes", o.in.axes},
                {"label", o.in.label}};
  j["seed"] = o.seed;
  j["weights"] = o.weights;
  {
    std::ostringstream rule;
    rule << "a term is negligible when its WV is below " << gm::kNegligibleFraction
         << " x (ci_high - ci_low) of the empirical WV at every scale";
    j["negligible_rule"] = rule.str();
  }
  j["structure"] = autoSel ? std::string("auto") : st::formatStructure(structure);
  j["conventions"] =
      "SI units; WN sigma, QN Q, RW gamma, DR omega per sample at input.rate_hz; GM sigma stationary, "
      "T in s; DR sign not identified by the WV (|omega|)";
  j["channels"] = json::array();
  for (const auto& c : fits) {
    json cj;
    cj["name"] = c.ch->name;
    cj["unit"] = navimpact::units::siUnit(c.ch->quantity);
    cj["model"] = st::formatTerms(c.fit.model.terms, 17);
    cj["objective"] = c.fit.objective;
    cj["weights"] = o.weights;
    cj["objective_r"] = c.fit.objective_fast;  // R's objective of this model
    std::vector<st::ProcessKind> k;
    for (const auto& t : c.fit.model.terms) k.push_back(t.kind);
    cj["structure"] = st::formatStructure(k);
    cj["ci_method"] = c.fit.ci_method;
    cj["converged"] = c.fit.converged;
    cj["starts"] = c.fit.starts;
    json terms = json::array();
    const std::vector<bool> neg = gm::negligibleTerms(c.fit.model, c.wv);
    for (std::size_t i = 0; i < c.fit.model.terms.size(); ++i) {
      json t = termJson(c.fit.model.terms[i], c.fit.ci[i]);
      t["negligible"] = static_cast<bool>(neg[i]);
      if (c.fit.model.terms[i].kind == st::ProcessKind::GM)  // AR1 form: phi = exp(-dt/T)
        t["phi"] = std::exp(-1.0 / (s.rate_hz * c.fit.model.terms[i].T));
      terms.push_back(t);
    }
    cj["terms"] = terms;
    cj["datasheet"] = datasheetJson(st::datasheetFigures(c.fit.model));
    if (autoSel) {
      json sel = json::array();
      for (const auto& r : c.ranking) {
        std::vector<st::ProcessKind> rk;
        for (const auto& t : r.fit.model.terms) rk.push_back(t.kind);
        sel.push_back({{"structure", st::formatStructure(rk)},
                       {"objective", r.fit.objective},
                       {"optimism", r.optimism},
                       {"criterion", r.criterion},
                       {"model", st::formatTerms(r.fit.model.terms)}});
      }
      cj["selection"] = sel;
      cj["selection_reason"] = c.why;
    }
    const Eigen::MatrixXd tw = st::haarWvTerms(c.fit.model, c.wv.tau);
    json terms_wv = json::array();
    for (Eigen::Index i = 0; i < tw.cols(); ++i) terms_wv.push_back(vec(tw.col(i)));
    cj["wv"] = {{"tau_s", vec(c.wv.tauSeconds())},
                {"wv", vec(c.wv.wv)},
                {"ci_low", vec(c.wv.ci_low)},
                {"ci_high", vec(c.wv.ci_high)},
                {"model_wv", vec(st::haarWv(c.fit.model, c.wv.tau))},
                {"terms_wv", terms_wv}};
    j["channels"].push_back(cj);
  }

  std::ostringstream comment;
  comment << "GMWM fit by navimpact " << NAVIMPACT_VERSION << " of " << input << ", structure " << j["structure"].get<std::string>()
          << ", seed " << o.seed;
  outs.writeText("model.yaml", st::toYaml(im, comment.str()));
  outs.writeText("fit.json", j.dump(2) + "\n");
  for (int sensor = 0; sensor < 2; ++sensor) {
    navimpact::plot::Figure fig;
    for (const auto& c : fits) {
      const bool gyro = c.ch->quantity == navimpact::units::Quantity::AngularRate;
      if (gyro == (sensor == 0)) fig.axes.push_back(wvAxes(c));
    }
    if (fig.axes.empty()) continue;
    const std::string sname = sensor == 0 ? "gyroscope" : "accelerometer";
    fig.rows = 1;
    fig.cols = static_cast<int>(fig.axes.size());
    fig.width = 650 * fig.cols;
    fig.height = 620;
    fig.title = "GMWM fit, " + sname + " — " + std::filesystem::path(input).filename().string();
    navimpact::plot::savePng(fig, outs.stage("fit_" + sname + ".png").string());
  }
  outs.commit();

  for (const auto& c : fits) {
    std::cout << c.ch->name << ": " << st::formatTerms(c.fit.model.terms) << "   ["
              << navimpact::units::siUnit(c.ch->quantity) << ", per sample at " << s.rate_hz << " Hz]\n";
    std::cout << "    objective " << c.fit.objective << " (" << gm::weightingName(c.fit.weighting) << " weights"
              << (c.fit.weighting == gm::Weighting::Fast ? "" : ", R objective " + std::to_string(c.fit.objective_fast))
              << ")  (" << c.fit.ci_method << " 95 % intervals in fit.json)\n";
    const std::vector<bool> neg = gm::negligibleTerms(c.fit.model, c.wv);
    for (std::size_t i = 0; i < neg.size(); ++i)
      if (neg[i])
        std::cout << "    negligible: term " << i + 1 << " " << st::formatTerms({c.fit.model.terms[i]})
                  << " (its WV is below " << gm::kNegligibleFraction
                  << " of the WV's 95 % CI width at every scale: the data cannot tell it from its absence;"
                  << (autoSel ? " kept: no ranked candidate lacks it)\n" : " kept: the requested structure has it)\n");
    if (autoSel) std::cout << "    " << c.why << "\n";
    std::istringstream lines(st::formatDatasheet(st::datasheetFigures(c.fit.model), c.ch->quantity));
    std::string l;
    while (std::getline(lines, l)) std::cout << "    " << l << "\n";
  }
  std::cout << "wrote";
  for (const auto& p : outs.finalPaths()) std::cout << " " << p.string();
  std::cout << "\n";
  return 0;
}

navimpact::cli::Registrar reg({
    "fit",
    "GMWM fit of IMU error models (WN, QN, RW, DR, GM, SIN) to a static recording",
    [](CLI::App& app) {
      auto o = std::make_shared<Opts>();
      navimpact::cli::addInputOptions(app, o->in);
      app.add_option("--channels", o->channels, "comma-separated channels to fit (default: all in the file)");
      app.add_option("--structure", o->structure,
                     "model structure for every channel, e.g. WN+GM+GM+DR, or 'auto' (WIC selection)")
          ->required();
      app.add_option("--max-gm", o->max_gm, "auto: largest number of GM terms among the candidates (0..3)");
      app.add_option("--bootstrap", o->bootstrap, "parametric bootstrap replicates for the intervals (0: asymptotic)");
      app.add_option("--intervals", o->intervals,
                     "95 % intervals without --bootstrap: profile (default; follows the objective along "
                     "GM/RW ridges) or asymptotic (delta method)");
      app.add_option("--weights", o->weights,
                     "GMWM weights: r (default, the R package's 1/(CI_hi-CI_lo)^2), model (iterated "
                     "model-based diagonal) or efficient (inverse of the full WV covariance)");
      app.add_option("--seed", o->seed, "seed of the bootstrap");
      app.add_option("--out", o->out, "output directory (model.yaml, fit.json, fit_*.png)")->required();
      navimpact::cli::addOverwriteFlag(app, o->overwrite);
      return [o]() -> int { return run(*o); };
    }});

}  // namespace
