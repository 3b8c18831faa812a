// Study outputs: metrics (JSON), time series (CSV), figures (PNG), report (Markdown).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "navimpact/analysis/study.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/plot/figure.hpp"
#include "navimpact/report/study_report.hpp"
#include "navimpact/report/timing.hpp"
#include "figures.hpp"

namespace navimpact::report {

using namespace analysis;

using nlohmann::json;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const char* kComp[9] = {"pos_N", "pos_E", "pos_D", "vel_N", "vel_E", "vel_D", "att_N", "att_E", "att_D"};
const char* kBlock[4] = {"pos", "vel", "att", "all"};
const int kDof[4] = {3, 3, 3, 9};

json jnum(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

/// Derived metrics of one study.
struct View {
  const StudyResults& r;
  double R;
  std::size_t E, O, M;
  explicit View(const StudyResults& res)
      : r(res), R(double(res.acc.runs)), E(res.meta.epochs.size()), O(res.meta.outages.size()),
        M(res.meta.labels.size()) {}
  const StudyAccumulator::Model& a(std::size_t m) const { return r.acc.models[m]; }
  double rms(std::size_t m, std::size_t k, int j) const { return std::sqrt(a(m).e2[9 * k + j] / R); }
  double sig(std::size_t m, std::size_t k, int j) const { return std::sqrt(a(m).s2[9 * k + j] / R); }
  double rmsH(std::size_t m, std::size_t k) const { return std::sqrt((a(m).e2[9 * k] + a(m).e2[9 * k + 1]) / R); }
  double sigH(std::size_t m, std::size_t k) const { return std::sqrt((a(m).s2[9 * k] + a(m).s2[9 * k + 1]) / R); }
  double rms3(std::size_t m, std::size_t k) const {
    return std::sqrt((a(m).e2[9 * k] + a(m).e2[9 * k + 1] + a(m).e2[9 * k + 2]) / R);
  }
  double anees(std::size_t m, std::size_t k, int b) const {
    const double n = a(m).n_valid[4 * k + b];
    return n > 0 ? a(m).nees[4 * k + b] / n : kNaN;
  }
  double cov(std::size_t m, std::size_t k, int b, bool c95) const {
    const double n = a(m).n_valid[4 * k + b];
    return n > 0 ? (c95 ? a(m).in95 : a(m).in68)[4 * k + b] / n : kNaN;
  }
  double t(std::size_t k) const { return r.meta.epochs[k]; }
  double rel(std::size_t k) const { return r.meta.epochs[k] - r.meta.t0; }
  bool inOutage(std::size_t k, std::size_t o) const {
    return t(k) > r.meta.outages[o].start_s + 1e-9 && t(k) <= r.meta.outages[o].end_s + 1e-9;
  }
  bool inAnyOutage(std::size_t k) const {
    for (std::size_t o = 0; o < O; ++o)
      if (inOutage(k, o)) return true;
    return false;
  }
  /// Last epoch <= outage end.
  std::size_t endEpoch(std::size_t o) const {
    std::size_t best = 0;
    for (std::size_t k = 0; k < E; ++k)
      if (t(k) <= r.meta.outages[o].end_s + 1e-9) best = k;
    return best;
  }
  double outageMeanAnees(std::size_t m, std::size_t o, int b) const {
    double s = 0;
    int n = 0;
    for (std::size_t k = 0; k < E; ++k)
      if (inOutage(k, o) && std::isfinite(anees(m, k, b))) {
        s += anees(m, k, b);
        ++n;
      }
    return n ? s / n : kNaN;
  }
  double fractionInBand(std::size_t m, std::size_t o, int b) const {
    const auto band = aneesBand(r.acc.runs, kDof[b]);
    int n = 0, in = 0;
    for (std::size_t k = 0; k < E; ++k)
      if (inOutage(k, o)) {
        ++n;
        const double v = anees(m, k, b);
        in += (v >= band.first && v <= band.second) ? 1 : 0;
      }
    return n ? double(in) / n : kNaN;
  }
  double gnssMeanAnees(std::size_t m, int b) const {
    double s = 0;
    int n = 0;
    for (std::size_t k = 1; k < E; ++k)
      if (!inAnyOutage(k) && std::isfinite(anees(m, k, b))) {
        s += anees(m, k, b);
        ++n;
      }
    return n ? s / n : kNaN;
  }
  std::size_t index(const std::string& label) const {
    const auto& L = r.meta.labels;
    return static_cast<std::size_t>(std::find(L.begin(), L.end(), label) - L.begin());
  }
};

/// Recommendation and white-noise threshold of one set at one outage.
struct SetVerdict {
  std::vector<bool> adequate;     // per set model
  std::vector<double> err_ratio, anees_ratio;
  std::string recommended;
  double wn_enough_below_s = kNaN;  // outage length below which WN-only is within the margin
  double wn_err_departs_s = kNaN, wn_sigma_departs_s = kNaN;
  bool wn_never_departs = false;
};

SetVerdict judge(const View& v, const ModelSetSpec& s, std::size_t o) {
  SetVerdict out;
  const double margin = v.r.meta.margin;
  const std::size_t ke = v.endEpoch(o), ref = v.index(s.reference), wn = v.index(s.white_noise);
  const double e_ref = v.rmsH(ref, ke), a_ref = v.outageMeanAnees(ref, o, 3);
  int best_states = std::numeric_limits<int>::max();
  for (const auto& l : s.models) {
    const std::size_t m = v.index(l);
    const double er = v.rmsH(m, ke) / e_ref, ar = v.outageMeanAnees(m, o, 3) / a_ref;
    const bool ok = er <= 1.0 + margin && ar <= 1.0 + margin;
    out.err_ratio.push_back(er);
    out.anees_ratio.push_back(ar);
    out.adequate.push_back(ok);
    if (ok && v.r.meta.states[m] < best_states) {
      best_states = v.r.meta.states[m];
      out.recommended = l;
    }
  }
  // White-noise-only model vs the reference, as a function of time into the
  // outage: the WN model is "enough" up to the last epoch after which its
  // horizontal error or predicted sigma stays outside the margin for good
  // (a persistent departure; isolated crossings early in the outage, where
  // both errors are at the GNSS noise level, do not count).
  const double start = v.r.meta.outages[o].start_s;
  double last_ok = 0.0;
  bool any_ok_after = true;
  for (std::size_t k = 0; k < v.E; ++k) {
    if (!v.inOutage(k, o)) continue;
    const double tau = v.t(k) - start;
    const double re = v.rmsH(wn, k) / v.rmsH(ref, k), rs = v.sigH(wn, k) / v.sigH(ref, k);
    const bool e_bad = std::abs(re - 1.0) > margin, s_bad = std::abs(rs - 1.0) > margin;
    if (!e_bad) out.wn_err_departs_s = kNaN;
    else if (std::isnan(out.wn_err_departs_s)) out.wn_err_departs_s = tau;
    if (!s_bad) out.wn_sigma_departs_s = kNaN;
    else if (std::isnan(out.wn_sigma_departs_s)) out.wn_sigma_departs_s = tau;
    any_ok_after = !(e_bad || s_bad);
    if (any_ok_after) last_ok = tau;
  }
  out.wn_never_departs = any_ok_after;
  out.wn_enough_below_s = last_ok;
  return out;
}

}  // namespace

void provenanceJson(const analysis::StudyHeader& h, json& j) {
  j["navimpact_version"] = h.version;
  json versions = json::object();
  for (const auto& [name, ver] : h.versions) versions[name] = ver;
  j["versions"] = versions;
  j["config_file"] = h.config_file;
  j["config_text"] = h.config_text;
  j["seed"] = h.seed;
}

namespace {

json buildJson(const View& v, bool with_cost) {
  const auto& meta = v.r.meta;
  json j;
  json study;
  provenanceJson(meta, study);
  study["runs"] = v.r.acc.runs;
  study["seed_rule"] =
      "run i uses seed_i = deriveSeed(seed, i); streams deriveSeed(seed_i, s): s=0 IMU errors (axis a: "
      "deriveSeed(., a)), 1 GNSS noise, 2 baro noise, 3 initial navigation error, 4 window of a measured recording";
  study["trajectory"] = meta.trajectory;
  study["t0_s"] = meta.t0;
  study["duration_s"] = meta.duration_s;
  study["imu_rate_hz"] = meta.imu_rate_hz;
  study["truth"] = meta.truth_description;
  study["settings"] = meta.settings;
  study["notices"] = meta.notices;
  json outs = json::array();
  for (const auto& o : meta.outages)
    outs.push_back({{"start_s", o.start_s - meta.t0}, {"end_s", o.end_s - meta.t0}, {"duration_s", o.end_s - o.start_s}});
  study["outages"] = outs;
  j["study"] = study;
  json band;
  for (int dof : {3, 9}) {
    const auto b = aneesBand(v.r.acc.runs, dof);
    band[std::to_string(dof)] = {b.first, b.second};
  }
  j["anees_band_95"] = band;
  j["coverage_nominal"] = {{"68", 0.6826894921370859}, {"95", 0.95}};

  json models = json::array();
  for (std::size_t m = 0; m < v.M; ++m) {
    json jm;
    jm["label"] = meta.labels[m];
    jm["model"] = meta.sources[m];
    jm["states"] = meta.states[m];
    json jo = json::array();
    for (std::size_t o = 0; o < v.O; ++o) {
      const std::size_t k = v.endEpoch(o);
      json e;
      e["t_s"] = v.rel(k);
      json re, ps, an, c68, c95;
      for (int c = 0; c < 9; ++c) {
        re[kComp[c]] = v.rms(m, k, c);
        ps[kComp[c]] = v.sig(m, k, c);
      }
      for (int b = 0; b < 4; ++b) {
        an[kBlock[b]] = jnum(v.anees(m, k, b));
        c68[kBlock[b]] = jnum(v.cov(m, k, b, false));
        c95[kBlock[b]] = jnum(v.cov(m, k, b, true));
      }
      e["rms_err"] = re;
      e["rms_pos_h_m"] = v.rmsH(m, k);
      e["rms_pos_3d_m"] = v.rms3(m, k);
      e["pred_sigma"] = ps;
      e["pred_sigma_pos_h_m"] = v.sigH(m, k);
      e["anees"] = an;
      e["coverage68"] = c68;
      e["coverage95"] = c95;
      json x;
      x["start_s"] = meta.outages[o].start_s - meta.t0;
      x["end_s"] = meta.outages[o].end_s - meta.t0;
      x["end"] = e;
      const auto& A = v.a(m);
      x["max_drift_h_m"] = {{"mean", A.drift_h[o] / v.R}, {"rms", std::sqrt(A.drift_h2[o] / v.R)}};
      x["max_drift_3d_mean_m"] = A.drift_3d[o] / v.R;
      json om, fb;
      for (int b = 0; b < 4; ++b) {
        om[kBlock[b]] = jnum(v.outageMeanAnees(m, o, b));
        fb[kBlock[b]] = jnum(v.fractionInBand(m, o, b));
      }
      x["anees_outage_mean"] = om;
      x["fraction_of_outage_epochs_anees_in_band"] = fb;
      jo.push_back(x);
    }
    jm["outages"] = jo;
    json g;
    for (int b = 0; b < 4; ++b) g[kBlock[b]] = jnum(v.gnssMeanAnees(m, b));
    jm["anees_mean_with_gnss"] = g;
    models.push_back(jm);
  }
  j["models"] = models;

  json sets = json::array();
  for (const auto& s : meta.sets) {
    json js;
    js["name"] = s.name;
    js["title"] = s.title;
    js["models"] = s.models;
    js["reference"] = s.reference;
    js["white_noise"] = s.white_noise;
    json per = json::array();
    for (std::size_t o = 0; o < v.O; ++o) {
      const SetVerdict sv = judge(v, s, o);
      json x;
      x["outage_end_s"] = meta.outages[o].end_s - meta.t0;
      x["recommended"] = sv.recommended;
      json ad = json::object();
      for (std::size_t i = 0; i < s.models.size(); ++i)
        ad[s.models[i]] = {{"adequate", bool(sv.adequate[i])},
                           {"err_ratio_to_reference", jnum(sv.err_ratio[i])},
                           {"anees_ratio_to_reference", jnum(sv.anees_ratio[i])}};
      x["models"] = ad;
      x["white_noise_enough_below_s"] = jnum(sv.wn_enough_below_s);
      x["white_noise_never_departs"] = sv.wn_never_departs;
      x["white_noise_error_departs_for_good_at_s"] = jnum(sv.wn_err_departs_s);
      x["white_noise_sigma_departs_for_good_at_s"] = jnum(sv.wn_sigma_departs_s);
      per.push_back(x);
    }
    js["per_outage"] = per;
    js["margin"] = meta.margin;
    sets.push_back(js);
  }
  j["sets"] = sets;

  if (with_cost) {
    json cost = json::array();
    for (std::size_t m = 0; m < v.M; ++m) {
      const auto& A = v.a(m);
      cost.push_back({{"label", meta.labels[m]},
                      {"states", meta.states[m]},
                      {"wall_s_per_run", A.wall_s / v.R},
                      {"us_per_step", A.steps > 0 ? 1e6 * A.wall_s / A.steps : 0.0}});
    }
    j["cost"] = cost;
  }
  return j;
}

// ---------------------------------------------------------------------------
// Figures

plot::Color colorOf(std::size_t i) { return plot::palette(static_cast<int>(i)); }

double scaleOf(int c) { return c >= 6 ? 1.0 / units::kDeg : 1.0; }

/// A panel over the window plotted around outage @p o (from plot_before_s
/// before its start to plot_after_s after its end; time from t0), the outage shaded.
plot::Axes outagePanel(const View& v, std::size_t o) {
  const auto& w = v.r.meta.outages[o];
  const double start = w.start_s - v.r.meta.t0, end = w.end_s - v.r.meta.t0;
  plot::Axes ax;
  ax.xlabel = "time [s]";
  ax.spans.push_back({"GNSS outage", start, end, {128, 128, 128}, 0.15});
  ax.xlim = std::make_pair(start - v.r.meta.plot_before_s, end + v.r.meta.plot_after_s);
  return ax;
}

void errorsFigure(const View& v, const ModelSetSpec& s, std::size_t o, const std::string& path) {
  const plot::Axes panel = outagePanel(v, o);
  const double x0 = panel.xlim->first, x1 = panel.xlim->second;
  plot::Figure fig = detail::figureOf(1800, 1300,
                                      s.title + ": actual error (RMS over " + std::to_string(v.r.acc.runs) +
                                          " runs, solid) and predicted sigma (dashed); GNSS outage shaded",
                                      3, 3);
  const char* rowName[3] = {"position", "velocity", "attitude"};
  const char* unit[3] = {"m", "m/s", "deg"};
  const char* axisName[3] = {"north", "east", "down"};
  for (int c = 0; c < 9; ++c) {
    plot::Axes ax = panel;
    ax.title = std::string(rowName[c / 3]) + " " + axisName[c % 3];
    ax.ylabel = std::string(rowName[c / 3]) + " error [" + unit[c / 3] + "]";
    ax.legend = c == 0 ? plot::LegendPos::TopLeft : plot::LegendPos::None;
    for (std::size_t i = 0; i < s.models.size(); ++i) {
      const std::size_t m = v.index(s.models[i]);
      plot::Series e, sg;
      e.label = s.models[i];
      e.color = sg.color = colorOf(i);
      sg.style = plot::LineStyle::Dashed;
      for (std::size_t k = 0; k < v.E; ++k) {
        const double t = v.rel(k);
        if (t < x0 || t > x1) continue;
        e.x.push_back(t);
        e.y.push_back(v.rms(m, k, c) * scaleOf(c));
        sg.x.push_back(t);
        sg.y.push_back(v.sig(m, k, c) * scaleOf(c));
      }
      ax.series.push_back(e);
      ax.series.push_back(sg);
    }
    fig.axes.push_back(ax);
  }
  plot::savePng(fig, path);
}

void neesFigure(const View& v, const ModelSetSpec& s, std::size_t o, const std::string& path) {
  const plot::Axes panel = outagePanel(v, o);
  const double x0 = panel.xlim->first, x1 = panel.xlim->second;
  plot::Figure fig = detail::figureOf(1600, 1100,
                                      s.title + ": average NEES over " + std::to_string(v.r.acc.runs) +
                                          " runs with its two-sided 95 % chi-square band",
                                      2, 2);
  const char* names[4] = {"position (3 dof)", "velocity (3 dof)", "attitude (3 dof)", "all nine (9 dof)"};
  for (int b = 0; b < 4; ++b) {
    plot::Axes ax = panel;
    ax.title = names[b];
    ax.ylabel = "ANEES";
    ax.logy = true;
    const auto band = aneesBand(v.r.acc.runs, kDof[b]);
    ax.hlines.push_back({"95 % band", band.first, {0, 0, 0}, plot::LineStyle::Dashed});
    ax.hlines.push_back({"", band.second, {0, 0, 0}, plot::LineStyle::Dashed});
    ax.legend = b == 0 ? plot::LegendPos::TopLeft : plot::LegendPos::None;
    double lo = band.first, hi = band.second;
    for (std::size_t i = 0; i < s.models.size(); ++i) {
      const std::size_t m = v.index(s.models[i]);
      plot::Series e;
      e.label = s.models[i];
      e.color = colorOf(i);
      for (std::size_t k = 0; k < v.E; ++k) {
        const double t = v.rel(k), a = v.anees(m, k, b);
        if (t < x0 || t > x1 || !(a > 0.0)) continue;
        e.x.push_back(t);
        e.y.push_back(a);
        lo = std::min(lo, a);
        hi = std::max(hi, a);
      }
      ax.series.push_back(e);
    }
    ax.ylim = std::make_pair(lo / 1.5, hi * 1.5);
    fig.axes.push_back(ax);
  }
  plot::savePng(fig, path);
}

void outageEndFigure(const View& v, const ModelSetSpec& s, const std::string& path) {
  plot::Figure fig;
  fig.width = 700 * static_cast<int>(v.O) + 300;
  fig.height = 800;
  fig.rows = 1;
  fig.cols = static_cast<int>(v.O);
  fig.title = s.title + ": horizontal position error at the outage end (bars: RMS over runs; crosses: predicted sigma)";
  for (std::size_t o = 0; o < v.O; ++o) {
    const std::size_t k = v.endEpoch(o);
    plot::Axes ax;
    ax.title = "outage " + formatReadable(v.r.meta.outages[o].start_s - v.r.meta.t0) + " to " +
               formatReadable(v.r.meta.outages[o].end_s - v.r.meta.t0) + " s";
    ax.xlabel = "model (legend order)";
    ax.ylabel = "horizontal position error [m]";
    double hi = 0.0;
    for (std::size_t i = 0; i < s.models.size(); ++i) {
      const std::size_t m = v.index(s.models[i]);
      plot::Series bar;
      bar.label = s.models[i];
      bar.color = colorOf(i);
      bar.width = std::max(8.0, 360.0 / double(s.models.size()));
      bar.x = {double(i + 1), double(i + 1)};
      bar.y = {0.0, v.rmsH(m, k)};
      plot::Series sg;
      sg.color = {0, 0, 0};
      sg.style = plot::LineStyle::None;
      sg.marker = plot::Marker::Cross;
      sg.width = 3.0;
      sg.x = {double(i + 1)};
      sg.y = {v.sigH(m, k)};
      hi = std::max({hi, v.rmsH(m, k), v.sigH(m, k)});
      ax.series.push_back(bar);
      ax.series.push_back(sg);
    }
    ax.xlim = std::make_pair(0.3, double(s.models.size()) + 0.7);
    ax.ylim = std::make_pair(0.0, hi * 1.35 + 1e-9);
    ax.legend = plot::LegendPos::TopLeft;
    fig.axes.push_back(ax);
  }
  plot::savePng(fig, path);
}

// ---------------------------------------------------------------------------
// Report

std::string bandText(const View& v, int dof) {
  const auto b = aneesBand(v.r.acc.runs, dof);
  return "[" + formatFixed(b.first, 2) + ", " + formatFixed(b.second, 2) + "]";
}

std::string report(const View& v, const std::vector<std::string>& figs_per_set_flat) {
  const auto& meta = v.r.meta;
  std::ostringstream md;
  md << "# Emulation study: which IMU error model is good enough?\n\n";
  md << "Monte Carlo comparison of candidate IMU error models inside a GNSS/baro-aided INS "
        "(error-state EKF), in the manner of the emulation study of Khaghani et al. (2019), judged by "
        "accuracy and by consistency (Cucci, Voirol, Khaghani & Guerrier 2023).\n\n";
  md << "## What was compared\n\n";
  md << "- trajectory: " << meta.trajectory << ", starting at file time " << formatReadable(meta.t0) << " s\n";
  md << "- true IMU errors on all six axes: " << meta.truth_description << "\n";
  md << "- " << v.r.acc.runs << " Monte Carlo runs, study seed " << meta.seed
     << "; every candidate model sees the same error realisation, GNSS/baro noise and initial error in a "
        "run (paired comparison); each run is a complete EKF run on its own estimates\n";
  for (std::size_t o = 0; o < v.O; ++o)
    md << "- GNSS outage " << o + 1 << ": from " << formatReadable(meta.outages[o].start_s - meta.t0) << " s to "
       << formatReadable(meta.outages[o].end_s - meta.t0) << " s (" << formatReadable(meta.outages[o].end_s - meta.outages[o].start_s)
       << " s without GNSS)\n";
  {
    std::istringstream s(meta.settings);
    std::string l;
    while (std::getline(s, l)) md << "- " << l << "\n";
  }
  for (const auto& n : meta.notices) md << "- note: " << n << "\n";
  md << "- configuration: `" << meta.config_file << "`; navimpact " << meta.version;
  for (const auto& [name, ver] : meta.versions)
    if (name != "navimpact" && name != "build_type") md << ", " << name << " " << ver;
  md << "\n\n";
  md << "Candidate models (the filter's IMU error model; an axis without a model is treated as perfect "
        "by the filter although the emulated data carry errors on all six axes):\n\n";
  md << "| model | filter states | error model |\n|---|---:|---|\n";
  for (std::size_t m = 0; m < v.M; ++m)
    md << "| " << meta.labels[m] << " | " << meta.states[m] << " | `" << meta.sources[m] << "` |\n";
  md << "\nHow to read the metrics: *RMS error* is the root mean square over runs of the actual error "
        "(estimate minus truth); *sigma* is the filter's predicted standard deviation (RMS over runs). "
        "*ANEES* is the average over runs of the normalised estimation error squared e' P^-1 e; for a "
        "consistent filter it lies inside the two-sided 95 % chi-square band, which for "
     << v.r.acc.runs << " runs is " << bandText(v, 3) << " for 3 dof (position, velocity, attitude) and "
     << bandText(v, 9)
     << " for 9 dof (all). Above the band the filter is over-optimistic (its sigma is too small), below it "
        "is pessimistic. *Coverage 95* is the fraction of runs whose error lies inside the predicted 95 % "
        "ellipsoid (nominal 0.95).\n\n";

  std::size_t fi = 0;
  for (const auto& s : meta.sets) {
    md << "## " << s.title << "\n\n";
    for (std::size_t o = 0; o < v.O; ++o) {
      const std::size_t k = v.endEpoch(o);
      const double dur = meta.outages[o].end_s - meta.outages[o].start_s;
      const SetVerdict sv = judge(v, s, o);
      md << "### Outage " << o + 1 << " (" << formatReadable(dur) << " s), values at its end (t = " << formatReadable(v.rel(k))
         << " s)\n\n";
      md << "| model | states | RMS horiz. pos. error [m] | predicted horiz. sigma [m] | mean max horiz. drift [m] "
            "| RMS yaw error [deg] | ANEES pos (band " << bandText(v, 3) << ") | ANEES all over the outage (mean) "
            "| coverage 95 pos | within margin of " << s.reference << " |\n";
      md << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n";
      for (std::size_t i = 0; i < s.models.size(); ++i) {
        const std::size_t m = v.index(s.models[i]);
        const auto& A = v.a(m);
        const double an = v.anees(m, k, 0);
        const auto band = aneesBand(v.r.acc.runs, 3);
        const std::string flag = an > band.second ? " (over-optimistic)" : an < band.first ? " (pessimistic)" : "";
        md << "| " << s.models[i] << " | " << meta.states[m] << " | " << formatFixed(v.rmsH(m, k), 2) << " | "
           << formatFixed(v.sigH(m, k), 2) << " | " << formatFixed(A.drift_h[o] / v.R, 2) << " | "
           << formatReadable(v.rms(m, k, 8) / units::kDeg) << " | " << formatReadable(an) << flag << " | "
           << formatReadable(v.outageMeanAnees(m, o, 3)) << " | " << formatFixed(v.cov(m, k, 0, true), 2) << " | "
           << (sv.adequate[i] ? "yes" : "no") << " (error x" << formatFixed(sv.err_ratio[i], 2) << ", ANEES x"
           << formatFixed(sv.anees_ratio[i], 2) << ") |\n";
      }
      md << "\n";
      md << "![errors](" << figs_per_set_flat[fi++] << ")\n\n";
      md << "![NEES](" << figs_per_set_flat[fi++] << ")\n\n";
      md << "**Recommendation for a " << formatReadable(dur) << " s outage:** ";
      if (sv.recommended.empty())
        md << "no model stays within " << formatReadable(100 * meta.margin) << " % of " << s.reference << ".\n\n";
      else
        md << "**" << sv.recommended << "** is the simplest model (fewest filter states) whose horizontal "
           << "position error at the outage end and whose ANEES over the outage stay within "
           << formatReadable(100 * meta.margin) << " % of the reference " << s.reference << ".\n\n";
      md << "**White noise alone (" << s.white_noise << ")** ";
      if (sv.wn_never_departs)
        md << "stays within " << formatReadable(100 * meta.margin) << " % of " << s.reference
           << " in horizontal error and predicted sigma for the whole " << formatReadable(dur) << " s outage.\n\n";
      else
        md << "is enough for outages shorter than about **" << formatReadable(sv.wn_enough_below_s) << " s**: after that "
           << "its horizontal position error "
           << (std::isnan(sv.wn_err_departs_s) ? std::string("never departs")
                                                : "departs from " + s.reference + "'s by more than " +
                                                      formatReadable(100 * meta.margin) + " % for good at " + formatReadable(sv.wn_err_departs_s) +
                                                      " s")
           << " and its predicted sigma "
           << (std::isnan(sv.wn_sigma_departs_s) ? std::string("never departs")
                                                  : "departs for good at " + formatReadable(sv.wn_sigma_departs_s) + " s")
           << " into the outage.\n\n";
      if (v.anees(v.index(s.reference), k, 0) > aneesBand(v.r.acc.runs, 3).second)
        md << "Caution: even the reference " << s.reference
           << " is over-optimistic here (ANEES above the band): the comparison within this set is relative; "
              "some error source the filter does not model dominates.\n\n";
    }
    md << "![error at outage end](" << figs_per_set_flat[fi++] << ")\n\n";
  }

  md << "## Summary across sets\n\n";
  md << "Effect of going from white noise only to the reference model within each set, at the end of each "
        "outage (error ratio > 1: the white-noise model drifts more; ANEES: over-optimism of each):\n\n";
  md << "| set | outage [s] | WN/Ref horizontal error | ANEES pos WN | ANEES pos Ref | recommended | WN enough below [s] |\n"
        "|---|---:|---:|---:|---:|---|---:|\n";
  for (const auto& s : meta.sets)
    for (std::size_t o = 0; o < v.O; ++o) {
      const std::size_t k = v.endEpoch(o), wn = v.index(s.white_noise), ref = v.index(s.reference);
      const SetVerdict sv = judge(v, s, o);
      md << "| " << s.title << " | " << formatReadable(meta.outages[o].end_s - meta.outages[o].start_s) << " | "
         << formatFixed(v.rmsH(wn, k) / v.rmsH(ref, k), 2) << " | " << formatReadable(v.anees(wn, k, 0)) << " | "
         << formatReadable(v.anees(ref, k, 0)) << " | " << (sv.recommended.empty() ? "none" : sv.recommended) << " | "
         << (sv.wn_never_departs ? ">= " : "") << formatReadable(sv.wn_enough_below_s) << " |\n";
    }
  md << "\n";
  md << "Files: `study.json` (all metrics per model and outage, configuration, seeds, versions), "
        "`timeseries.csv` (per model and epoch: RMS error, predicted sigma, ANEES, coverage), the figures above; "
        "`timing.json` the cost per model (wall time per run, us per filter step).\n";
  return md.str();
}

std::string timeseriesCsv(const View& v) {
  std::ostringstream o;
  o.precision(9);
  o << "model,t_s,in_outage";
  for (int c = 0; c < 9; ++c) o << ",rms_" << kComp[c];
  for (int c = 0; c < 9; ++c) o << ",sigma_" << kComp[c];
  for (int b = 0; b < 4; ++b) o << ",anees_" << kBlock[b];
  for (int b = 0; b < 4; ++b) o << ",cov68_" << kBlock[b];
  for (int b = 0; b < 4; ++b) o << ",cov95_" << kBlock[b];
  o << "\n# units: position m, velocity m/s, attitude rad; t_s from the trajectory start\n";
  for (std::size_t m = 0; m < v.M; ++m)
    for (std::size_t k = 0; k < v.E; ++k) {
      o << '"' << v.r.meta.labels[m] << '"' << ',' << v.rel(k) << ',' << (v.inAnyOutage(k) ? 1 : 0);
      for (int c = 0; c < 9; ++c) o << ',' << v.rms(m, k, c);
      for (int c = 0; c < 9; ++c) o << ',' << v.sig(m, k, c);
      for (int b = 0; b < 4; ++b) o << ',' << v.anees(m, k, b);
      for (int b = 0; b < 4; ++b) o << ',' << v.cov(m, k, b, false);
      for (int b = 0; b < 4; ++b) o << ',' << v.cov(m, k, b, true);
      o << '\n';
    }
  return o.str();
}

}  // namespace

std::string studyMetricsJson(const StudyResults& r) {
  const View v(r);
  return buildJson(v, false).dump(1, ' ', false, nlohmann::json::error_handler_t::replace);
}

void writeStudyOutputs(const StudyResults& r, OutputSet& out) {
  if (r.acc.runs == 0) throw Error("study: no runs to report");
  const View v(r);
  out.writeText("study.json", buildJson(v, false).dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  {  // wall-clock figures apart, so that two identical runs give identical result files
    json cost = json::array();
    for (std::size_t m = 0; m < v.M; ++m) {
      const auto& A = v.a(m);
      cost.push_back({{"label", r.meta.labels[m]},
                      {"states", r.meta.states[m]},
                      {"wall_s_per_run", A.wall_s / v.R},
                      {"us_per_step", A.steps > 0 ? 1e6 * A.wall_s / A.steps : 0.0}});
    }
    writeTiming(out, json{{"cost", cost}});
  }
  out.writeText("timeseries.csv", timeseriesCsv(v));
  std::vector<std::string> figs;
  for (const auto& s : r.meta.sets) {
    for (std::size_t o = 0; o < v.O; ++o) {
      const std::string e = "fig_" + s.name + "_errors_o" + std::to_string(o + 1) + ".png";
      const std::string n = "fig_" + s.name + "_nees_o" + std::to_string(o + 1) + ".png";
      errorsFigure(v, s, o, out.stage(e).string());
      neesFigure(v, s, o, out.stage(n).string());
      figs.push_back(e);
      figs.push_back(n);
    }
    const std::string b = "fig_" + s.name + "_outage_end.png";
    outageEndFigure(v, s, out.stage(b).string());
    figs.push_back(b);
  }
  out.writeText("report.md", report(v, figs));
}

}  // namespace navimpact::report
