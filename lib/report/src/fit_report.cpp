// Outputs of navimpact fit: model.yaml, fit.json, WV figures, console summary.
#include "navimpact/report/fit_report.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include <nlohmann/json.hpp>

#include "navimpact/core/format.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/plot/figure.hpp"
#include "navimpact/stochastic/datasheet.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

namespace navimpact::report {

namespace {

namespace st = navimpact::stochastic;
namespace gm = navimpact::gmwm;
using json = nlohmann::json;

std::vector<double> vec(const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

std::vector<st::ProcessKind> kindsOf(const st::Model& m) {
  std::vector<st::ProcessKind> k;
  for (const auto& t : m.terms) k.push_back(t.kind);
  return k;
}

/// The channels of the model no fit gave a term (absent from the input, or
/// left out by --channels): "none" in model.yaml, a perfect sensor in a simulation.
std::vector<std::string> unfitted(const gm::RecordingFit& f) {
  std::vector<std::string> out;
  for (const char* name : kChannelNames) {
    bool fitted = false;
    for (const auto& c : f.channels) fitted = fitted || c.name == name;
    if (!fitted) out.emplace_back(name);
  }
  return out;
}

std::string unfittedNote(const gm::RecordingFit& f) {
  const auto u = unfitted(f);
  if (u.empty()) return {};
  std::string list;
  for (const auto& n : u) list += (list.empty() ? "" : ", ") + n;
  return list + (u.size() == 1 ? " was" : " were") +
         " not fitted (not in the input, or left out by --channels): none in model.yaml, a perfect sensor in a simulation";
}

std::string structureText(const gm::RecordingFit& f) {
  return f.options.structure == "auto" ? std::string("auto")
                                       : st::formatStructure(st::parseStructure(f.options.structure));
}

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
  if (f.noise_density_gms > 0) {
    d["noise_density_gms"] = f.noise_density_gms;
    d["noise_density_gm_share"] = f.noise_density_gm_share;
  }
  if (!f.bias_instability_warning.empty()) d["bias_instability_warning"] = f.bias_instability_warning;
  return d;
}

/// Datasheet figures of a channel's model, the bias-instability search up to
/// the longest averaging time its record supports (half the largest WV scale).
st::DatasheetFigures channelDatasheet(const gm::ChannelFit& c) {
  const double max_s = c.wv.scales() > 0 ? 0.5 * c.wv.tau[c.wv.scales() - 1] / c.wv.rate_hz : 0.0;
  return st::datasheetFigures(c.fit.model, max_s);
}

/// Misses of the model WV beyond what chance gives (gmwm::outsideCiChance < 0.05).
bool outsideCiBeyondChance(const gm::ChannelFit& c) {
  return gm::outsideCiChance(static_cast<int>(c.outside_ci.size()), c.wv.scales()) < 0.05;
}

/// "model WV outside the 95 % CI at 3 of 19 scales (tau = 0.02, 0.04, 1311 s; ...)".
std::string outsideCiText(const gm::ChannelFit& c) {
  if (c.outside_ci.empty()) return "";
  std::ostringstream os;
  os.precision(3);
  os << "model WV outside the 95 % CI at " << c.outside_ci.size() << " of " << c.wv.scales()
     << " scales (tau =";
  for (std::size_t k = 0; k < c.outside_ci.size(); ++k)
    os << (k ? ", " : " ") << c.wv.tau[c.outside_ci[k]] / c.wv.rate_hz;
  const double chance = gm::outsideCiChance(static_cast<int>(c.outside_ci.size()), c.wv.scales());
  os << " s); a correct model misses that many with probability " << chance;
  if (outsideCiBeyondChance(c))
    os << ": the model does not describe the data there (navimpact diagnose names what is missing)";
  else
    os << ": consistent with chance";
  return os.str();
}

std::string fitJson(const gm::RecordingFit& f, const std::string& input_json) {
  const bool autoSel = f.options.structure == "auto";
  json j;
  j["input"] = json::parse(input_json);
  j["seed"] = f.options.seed;
  j["weights"] = f.options.weights;
  j["estimator"] = f.options.robust
                       ? json{{"wv", "robust (Tukey biweight M-scale of the wavelet coefficients) of the record with "
                                     "its isolated spikes replaced (second difference beyond the Bonferroni 1 % "
                                     "threshold of its MAD scale; channels[].despiked_samples)"},
                              {"eff", f.options.eff},
                              {"reference", "Guerrier, Molinari & Victoria-Feser (2014), robust GMWM"}}
                       : json{{"wv", "classical (mean of squares)"}};
  {
    std::ostringstream rule;
    rule << "a term is negligible when its WV is below " << gm::kNegligibleFraction
         << " x (ci_high - ci_low) of the empirical WV at every scale";
    j["negligible_rule"] = rule.str();
  }
  j["structure"] = structureText(f);
  j["unfitted_channels"] = unfitted(f);
  j["conventions"] =
      "SI units; WN sigma, QN Q, RW gamma, DR omega per sample at input.rate_hz; GM sigma stationary, "
      "T in s; DR sign not identified by the WV (|omega|)";
  j["channels"] = json::array();
  for (const auto& c : f.channels) {
    json cj;
    cj["name"] = c.name;
    cj["unit"] = units::siUnit(c.quantity);
    cj["model"] = st::formatTerms(c.fit.model.terms, 17);
    if (f.options.robust) cj["despiked_samples"] = c.despiked;
    cj["objective"] = c.fit.objective;
    cj["weights"] = f.options.weights;
    cj["objective_r"] = c.fit.objective_fast;  // R's objective of this model
    cj["structure"] = st::formatStructure(kindsOf(c.fit.model));
    cj["ci_method"] = c.fit.ci_method;
    cj["converged"] = c.fit.converged;
    cj["starts"] = c.fit.starts;
    json terms = json::array();
    for (std::size_t i = 0; i < c.fit.model.terms.size(); ++i) {
      json t = termJson(c.fit.model.terms[i], c.fit.ci[i]);
      t["negligible"] = static_cast<bool>(c.negligible[i]);
      if (c.fit.model.terms[i].kind == st::ProcessKind::GM)  // AR1 form: phi = exp(-dt/T)
        t["phi"] = std::exp(-1.0 / (f.rate_hz * c.fit.model.terms[i].T));
      terms.push_back(t);
    }
    cj["terms"] = terms;
    cj["datasheet"] = datasheetJson(channelDatasheet(c));
    json out_ci = json::array();
    for (int j : c.outside_ci)
      out_ci.push_back({{"tau_s", c.wv.tau[j] / c.wv.rate_hz},
                        {"wv", c.wv.wv[j]},
                        {"model_wv", st::haarWv(c.fit.model, c.wv.tau.segment(j, 1))[0]},
                        {"ci_low", c.wv.ci_low[j]},
                        {"ci_high", c.wv.ci_high[j]}});
    cj["scales_outside_ci"] = out_ci;
    cj["scales_outside_ci_chance"] = gm::outsideCiChance(static_cast<int>(c.outside_ci.size()), c.wv.scales());
    json warnings = json::array();
    if (outsideCiBeyondChance(c)) warnings.push_back(outsideCiText(c));
    if (!c.white_noise_note.empty()) warnings.push_back(c.white_noise_note);
    if (!c.slow_gm_note.empty()) warnings.push_back(c.slow_gm_note);
    cj["warnings"] = warnings;
    if (autoSel) {
      json sel = json::array();
      for (const auto& r : c.ranking) {
        sel.push_back({{"structure", st::formatStructure(kindsOf(r.fit.model))},
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
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

/// One WV panel in the style of the paper's Figures 1-4.
plot::Axes wvAxes(const gm::ChannelFit& c) {
  namespace pl = navimpact::plot;
  pl::Axes ax;
  ax.logx = ax.logy = true;
  ax.title = c.name + ": " + st::formatStructure(kindsOf(c.fit.model));
  const std::string u = units::siUnit(c.quantity);
  ax.xlabel = "scale τ [s]";
  ax.ylabel = "wavelet variance [(" + u + ")²]";
  const auto tau_s = vec(c.wv.tauSeconds());
  ax.bands.push_back({"95% CI", tau_s, vec(c.wv.ci_low), vec(c.wv.ci_high), pl::palette(0), 0.2});
  ax.series.push_back({"empirical WV", tau_s, vec(c.wv.wv), pl::palette(0), pl::LineStyle::Solid,
                       pl::Marker::FilledCircle, 2.0});
  const Eigen::MatrixXd terms = st::haarWvTerms(c.fit.model, c.wv.tau);
  for (Eigen::Index i = 0; i < terms.cols(); ++i) {
    const auto& p = c.fit.model.terms[static_cast<std::size_t>(i)];
    std::string lab = st::kindName(p.kind);
    if (p.kind == st::ProcessKind::GM) {
      char b[48];
      std::snprintf(b, sizeof b, "GM (T = %.3g s)", p.T);
      lab = b;
    }
    if (c.negligible[static_cast<std::size_t>(i)]) lab += " (negligible)";
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

}  // namespace

void writeFitOutputs(const gm::RecordingFit& f, const std::string& input_json,
                     const std::string& version, OutputSet& out) {
  std::ostringstream comment;
  comment << "GMWM fit by navimpact " << version << " of " << f.source << ", structure "
          << structureText(f) << ", seed " << f.options.seed;
  for (const auto& c : f.channels)  // what model.yaml alone would not say
    if (!c.slow_gm_note.empty()) comment << "\nnote, " << c.name << ": " << c.slow_gm_note;
  if (const std::string u = unfittedNote(f); !u.empty()) comment << "\nnote: " << u;
  out.writeText("model.yaml", st::toYaml(f.model, comment.str()));
  out.writeText("fit.json", fitJson(f, input_json));
  for (int sensor = 0; sensor < 2; ++sensor) {
    plot::Figure fig;
    for (const auto& c : f.channels) {
      const bool gyro = c.quantity == units::Quantity::AngularRate;
      if (gyro == (sensor == 0)) fig.axes.push_back(wvAxes(c));
    }
    if (fig.axes.empty()) continue;
    const std::string sname = sensor == 0 ? "gyroscope" : "accelerometer";
    fig.rows = 1;
    fig.cols = static_cast<int>(fig.axes.size());
    fig.width = 650 * fig.cols;
    fig.height = 620;
    fig.title = "GMWM fit, " + sname + " — " + std::filesystem::path(f.source).filename().string();
    plot::savePng(fig, out.stage("fit_" + sname + ".png").string());
  }
}

std::string fitSummary(const gm::RecordingFit& f) {
  const bool autoSel = f.options.structure == "auto";
  std::ostringstream os;
  for (const auto& c : f.channels) {
    os << c.name << ": " << st::formatTerms(c.fit.model.terms) << "   [" << units::siUnit(c.quantity)
       << ", per sample at " << f.rate_hz << " Hz]\n";
    os << "    objective " << c.fit.objective << " (" << (f.options.robust ? "robust WV, " : "")
       << gm::weightingName(c.fit.weighting) << " weights"
       << (c.fit.weighting == gm::Weighting::Fast ? "" : ", R objective " + formatNumber(c.fit.objective_fast))
       << ")  (" << c.fit.ci_method << " 95 % intervals in fit.json)\n";
    for (std::size_t i = 0; i < c.negligible.size(); ++i)
      if (c.negligible[i])
        os << "    negligible: term " << i + 1 << " " << st::formatTerms({c.fit.model.terms[i]})
           << " (its WV is below " << gm::kNegligibleFraction
           << " of the WV's 95 % CI width at every scale: the data cannot tell it from its absence;"
           << (autoSel ? " kept: no ranked candidate lacks it)\n" : " kept: the requested structure has it)\n");
    if (autoSel) os << "    " << c.why << "\n";
    if (!c.outside_ci.empty())
      os << "    " << (outsideCiBeyondChance(c) ? "warning: " : "note: ") << outsideCiText(c) << "\n";
    if (!c.white_noise_note.empty()) os << "    note: " << c.white_noise_note << "\n";
    if (!c.slow_gm_note.empty()) os << "    note: " << c.slow_gm_note << "\n";
    std::istringstream lines(st::formatDatasheet(channelDatasheet(c), c.quantity));
    std::string l;
    while (std::getline(lines, l)) os << "    " << l << "\n";
  }
  if (const std::string u = unfittedNote(f); !u.empty()) os << "note: " << u << "\n";
  return os.str();
}

}  // namespace navimpact::report
