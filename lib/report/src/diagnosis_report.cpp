// diagnosis.json, report.md and figures of navimpact diagnose.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include <nlohmann/json.hpp>

#include "navimpact/analysis/diagnosis.hpp"
#include "navimpact/plot/figure.hpp"
#include "navimpact/report/diagnosis_report.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

namespace navimpact::report {

using namespace analysis;

namespace {

using nlohmann::json;

json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json findingJson(const Finding& f) {
  json j;
  j["channel"] = f.channel;
  j["cause"] = causeName(f.cause);
  json p = json::object();
  for (const auto& kv : f.params) p[kv.first] = num(kv.second);
  if (f.cause == Cause::Outliers) p["times_s"] = f.times_s;
  j["params"] = p;
  j[f.range_key] = {num(f.range_lo), num(f.range_hi)};
  if (f.T_interval_s) j["T_interval_s"] = {num(f.T_interval_s->first), num(f.T_interval_s->second)};
  j["direction"] = f.direction;
  j["explanation"] = f.explanation;
  j["action"] = f.action;
  j["statistic"] = num(f.statistic);
  j["threshold"] = num(f.threshold);
  j["p_value"] = num(f.p_value);
  if (!f.intervals.empty()) {
    json iv = json::object();
    for (const auto& kv : f.intervals) iv[kv.first] = {num(kv.second.first), num(kv.second.second)};
    j["intervals_95"] = iv;
  }
  if (!f.evidence.empty()) j["evidence"] = f.evidence;
  if (!f.harmonics_hz.empty()) j["harmonics_hz"] = f.harmonics_hz;
  if (f.event >= 0) j["event"] = f.event;
  return j;
}

json scalesJson(const std::vector<ScaleCheck>& s) {
  json a = json::array();
  for (const auto& c : s) {
    a.push_back({{"tau_s", c.tau_s},
                 {"measured", num(c.measured)},
                 {"model", num(c.model)},
                 {"ci", {num(c.ci_low), num(c.ci_high)}},
                 {"envelope", {num(c.env_low), num(c.env_high)}},
                 {"dof", num(c.dof)},
                 {"ratio", num(c.ratio)},
                 {"ci_widths", num(c.ci_widths)},
                 {"p_value", num(c.p_value)},
                 {"outside_95", c.outside95},
                 {"significant", c.significant}});
  }
  return a;
}

std::string modelText(const stochastic::Model& m) {
  return m.empty() ? "none" : stochastic::formatTerms(m.terms, 4);
}

}  // namespace

std::string diagnosisJson(const Diagnosis& d, const std::string& input_json) {
  json j;
  j["input"] = input_json.empty() ? json::object() : json::parse(input_json);
  j["input"]["samples"] = d.samples;
  j["input"]["rate_hz"] = d.rate_hz;
  j["verdict"] = d.adequate ? "adequate" : "inadequate";
  j["notices"] = d.notices;
  j["method"] = {
      {"alpha_familywise", d.options.alpha},
      {"alpha_split", {{"wv", 0.4}, {"spectrum", 0.2}, {"level_shift", 0.2}, {"outliers", 0.2}}},
      {"simulations", d.options.simulations},
      {"seed", d.options.seed},
      {"cause_selection", "gamma-deviance WV fit of each family on the first half, AIC"},
      {"extension", "GMWM refit of the extended structure warm-started at the user's "
                    "parameters plus the findings (first half for the gain, whole record for "
                    "the model file), kept when it does not raise the deviance"},
      {"gain", "held-out second half (first-half fit) when a process was fitted"}};
  json chans = json::array();
  for (const auto& c : d.channels) {
    json cj;
    cj["name"] = c.name;
    cj["verdict"] = c.adequate ? "adequate" : "inadequate";
    json fs = json::array();
    for (const auto& f : c.findings) fs.push_back(findingJson(f));
    cj["findings"] = fs;
    cj["model_before"] = modelText(c.model_before);
    cj["model_after"] = modelText(c.model_after);
    cj["model_after_first_half"] = modelText(c.model_after_half);
    cj["wv_objective"] = {{"before", num(c.gain.objective_before)},
                          {"after", num(c.gain.objective_after)}};
    cj["scales_outside_ci"] = {{"before", c.gain.outside_before},
                               {"after", c.gain.outside_after},
                               {"of", c.gain.scales}};
    cj["gain"] = {{"basis", c.gain.basis},
                  {"deviance", {{"before", num(c.gain.deviance_before)},
                                {"after", num(c.gain.deviance_after)}}},
                  {"added_params", c.gain.added_params},
                  {"test", c.gain.test},
                  {"z", num(c.gain.z)},
                  {"p_value", num(c.gain.p_value)},
                  {"direction", c.gain.direction},
                  {"significant", c.gain.significant}};
    if (!c.refit_full.empty())
      cj["gmwm_refit"] = {{"whole_record", c.refit_full}, {"first_half", c.refit_half}};
    cj["wv_per_scale_p_threshold"] = c.wv_threshold_p;
    cj["scales"] = scalesJson(c.scales);
    cj["spectrum"] = {{"method", "Hann periodogram of the whole record vs max(model PSD, local level)"},
                      {"bin_hz", c.spectrum.bin_hz},
                      {"bins_tested", c.spectrum.bins_tested},
                      {"band_hz", {c.spectrum.f_min_hz, c.spectrum.f_max_hz}},
                      {"line_threshold_ratio", c.spectrum.threshold_ratio},
                      {"lines_hz", c.line_freqs_hz}};
    if (!c.notes.empty()) cj["notes"] = c.notes;
    chans.push_back(cj);
  }
  j["channels"] = chans;
  json evs = json::array();
  for (const auto& e : d.events)
    evs.push_back({{"cause", causeName(e.cause)}, {"t_s", e.t_s}, {"duration_s", e.duration_s},
                   {"channels", e.channels}, {"sizes", e.sizes}});
  j["events"] = evs;
  if (d.navigation) {
    const NavGain& g = *d.navigation;
    json nav;
    nav["trajectory"] = g.trajectory;
    nav["truth"] = g.truth;
    nav["filter_after"] = g.filter_after;
    nav["settings"] = g.settings;
    if (!g.filter_note.empty()) nav["filter_note"] = g.filter_note;
    nav["imu_rate_hz"] = g.imu_rate_hz;
    nav["runs"] = g.runs;
    nav["seed"] = g.seed;
    nav["window_offsets_s"] = g.window_offsets_s;
    nav["significance"] =
        "paired over runs (same measured window, GNSS/baro noise and initial error for both "
        "models): exact two-sided sign test on the horizontal error at the outage end, p < 0.05";
    json os = json::array();
    for (const auto& o : g.outages) {
      auto pair = [](double b, double a) { return json{{"before", num(b)}, {"after", num(a)}}; };
      json oj;
      oj["start_s"] = o.start_s;
      oj["duration_s"] = o.duration_s;
      oj["horizontal_error_m"] = pair(o.mean_h_before, o.mean_h_after);
      oj["vertical_error_m"] = pair(o.mean_v_before, o.mean_v_after);
      oj["max_drift_m"] = pair(o.mean_drift_before, o.mean_drift_after);
      oj["nees"] = {{"before", num(o.anees_before)},
                    {"after", num(o.anees_after)},
                    {"band", {o.nees_band.first, o.nees_band.second}},
                    {"block", "position (3 dof), mean over runs at the outage end"}};
      oj["per_run"] = {{"horizontal_error_m", {{"before", o.h_before}, {"after", o.h_after}}},
                       {"vertical_error_m", {{"before", o.v_before}, {"after", o.v_after}}},
                       {"max_drift_m", {{"before", o.drift_before}, {"after", o.drift_after}}},
                       {"nees", {{"before", o.nees_before}, {"after", o.nees_after}}}};
      oj["runs_better_after"] = o.wins;
      oj["sign_test_p"] = num(o.sign_p);
      oj["paired_t_p"] = num(o.t_p);
      oj["significant"] = o.significant;
      os.push_back(oj);
    }
    nav["outages"] = os;
    nav["wall_s"] = g.wall_s;
    j["navigation"] = nav;
  }
  return j.dump(2) + "\n";
}

std::string diagnosisReport(const Diagnosis& d, const std::vector<std::string>& figures) {
  std::ostringstream r;
  r << "# IMU error model diagnosis\n\n";
  r << "Input: `" << d.source << "`, " << d.samples << " samples at " << fmtNum(d.rate_hz, 6)
    << " Hz (" << fmtNum(d.samples / d.rate_hz, 5) << " s). Model: `" << d.model_before.source
    << "`.\n\n";
  for (const auto& n : d.notices) r << "> Notice: " << n << "\n\n";
  r << "**Verdict: " << (d.adequate ? "adequate" : "inadequate") << "** — ";
  int nf = 0;
  for (const auto& c : d.channels) nf += static_cast<int>(c.findings.size());
  if (d.adequate)
    r << "on every channel the measured data are consistent with simulations of the model "
         "(wavelet variance, spectrum, level shifts, spikes; family-wise level "
      << d.options.alpha * 100 << " % for the whole record).\n\n";
  else
    r << nf << " finding(s); what the simulation gets wrong and why is listed per channel "
         "below.\n\n";
  r << "## Summary\n\n| channel | verdict | findings | model before | model after | "
       "scales outside CI (before → after) | WV objective (before → after) | gain |\n"
       "|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : d.channels) {
    std::string causes;
    for (const auto& f : c.findings) causes += std::string(causes.empty() ? "" : ", ") + causeName(f.cause);
    r << "| " << c.name << " | " << (c.adequate ? "adequate" : "inadequate") << " | "
      << (causes.empty() ? "—" : causes) << " | `" << modelText(c.model_before) << "` | `"
      << modelText(c.model_after) << "` | " << c.gain.outside_before << " → "
      << c.gain.outside_after << " of " << c.gain.scales << " | "
      << fmtNum(c.gain.objective_before, 3) << " → " << fmtNum(c.gain.objective_after, 3) << " | "
      << (c.findings.empty() ? "—"
                             : (c.gain.significant ? "significant" : "not significant") +
                                   std::string(" (") + c.gain.basis + ", p = " +
                                   fmtNum(c.gain.p_value, 2) + ")")
      << " |\n";
  }
  r << "\n## Findings\n\n";
  for (const auto& c : d.channels) {
    if (c.findings.empty()) continue;
    r << "### " << c.name << "\n\n";
    for (const auto& f : c.findings) {
      r << "- **" << causeName(f.cause) << "** (";
      bool first = true;
      for (const auto& kv : f.params) {
        r << (first ? "" : ", ") << kv.first << " = " << fmtNum(kv.second, 4);
        first = false;
      }
      r << "): " << f.explanation << " *What to do:* " << f.action << ".\n";
    }
    r << "\n| tau [s] | measured | model | 95 % CI | ratio | CI widths outside | significant |\n"
         "|---|---|---|---|---|---|---|\n";
    for (const auto& s : c.scales)
      if (s.outside95)
        r << "| " << fmtNum(s.tau_s, 4) << " | " << fmtNum(s.measured, 3) << " | "
          << fmtNum(s.model, 3) << " | " << fmtNum(s.ci_low, 3) << " – " << fmtNum(s.ci_high, 3)
          << " | " << fmtNum(s.ratio, 3) << " | " << fmtNum(s.ci_widths, 3) << " | "
          << (s.significant ? "yes" : "no") << " |\n";
    r << "\n";
  }
  if (d.navigation) {
    const NavGain& g = *d.navigation;
    r << "## Navigation gain\n\n"
      << "Navigation along `" << g.trajectory << "` emulated with the **measured** errors as the "
      << "truth: " << g.truth << ". The filter ran once with the model before and once with "
      << g.filter_after << ", on the same " << g.runs << " realisations (seed " << g.seed
      << "). " << g.settings << "."
      << (g.filter_note.empty() ? std::string() : " Note: " + g.filter_note + ".") << "\n\n"
      << "| outage | horizontal error at end [m] | vertical error at end [m] | max horizontal "
         "drift [m] | position NEES at end (95 % band) | runs better after | gain |\n"
         "|---|---|---|---|---|---|---|\n";
    for (const auto& o : g.outages) {
      auto inBand = [&](double v) {
        return v >= o.nees_band.first && v <= o.nees_band.second ? "" : " (outside)";
      };
      r << "| " << fmtNum(o.start_s, 5) << " s + " << fmtNum(o.duration_s, 4) << " s | "
        << fmtNum(o.mean_h_before, 3) << " → " << fmtNum(o.mean_h_after, 3) << " | "
        << fmtNum(o.mean_v_before, 3) << " → " << fmtNum(o.mean_v_after, 3) << " | "
        << fmtNum(o.mean_drift_before, 3) << " → " << fmtNum(o.mean_drift_after, 3) << " | "
        << fmtNum(o.anees_before, 3) << inBand(o.anees_before) << " → " << fmtNum(o.anees_after, 3)
        << inBand(o.anees_after) << " (" << fmtNum(o.nees_band.first, 3) << "–"
        << fmtNum(o.nees_band.second, 3) << ") | " << o.wins << " of " << g.runs << " | "
        << (o.significant ? "significant" : "not significant") << " (sign test p = "
        << fmtNum(o.sign_p, 2) << ", paired t p = " << fmtNum(o.t_p, 2) << ") |\n";
    }
    r << "\nErrors are means over the runs; the NEES band is the two-sided 95 % band of the "
         "mean of " << g.runs << " chi-square(3) values (a consistent filter lies inside it). A "
         "gain is called significant only when the extension gives the smaller horizontal error "
         "at the outage end in significantly more runs than chance (exact sign test, p < 0.05); "
         "the runs share one recording, so they are not fully independent (overlapping windows "
         "when the record is short).\n\n";
  }
  r << "## Method\n\n"
       "- **What the simulation gets wrong:** the model is simulated "
    << d.options.simulations << " times (seed " << d.options.seed
    << ") at the data's length and rate; the measured Haar WV is compared with the "
       "simulated envelope (min–max) and with the model's theoretical WV and its chi-square "
       "CI (dof eta_j = max(M_j/2^j, 1), lowered to the dof seen in the simulations where "
       "smaller). A scale is significant when its two-sided p-value is below the "
       "family-wise level (Bonferroni over scales and channels).\n"
       "- **Where the WV is blind:** isolated spikes (robust z of the second difference, "
       "Bonferroni over samples), level shifts (maximum Haar coefficient over positions "
       "against its robust scale, scales 2^3.. samples), and narrow-band lines (Welch "
       "periodogram against a running-median background, chi-square threshold, Bonferroni "
       "over bins). These are removed before the WV tests so that they do not pose as "
       "Gauss-Markov or random-walk terms.\n"
       "- **Cause:** each family (WN, QN, RW, DR, GM, or a retuned term of the model) is "
       "fitted to the WV with the other terms kept, on the first half of the record; the "
       "smallest AIC (chi-square deviance + 2 × parameters) names the cause; it is refitted "
       "on the whole record for the finding's parameters. The extended structure is then "
       "refitted by GMWM (warm start: the user's parameters plus the findings' estimates), on "
       "the first half for the held-out comparison and on the whole record for "
       "model_extended.yaml; a refit that raises the chi-square deviance on its own fit data "
       "is not kept (see gmwm_refit in diagnosis.json).\n"
       "- **Gain:** the user's model and the first-half extension are both evaluated on the "
       "held-out second half (GMWM objective with the R package's fast weights, deviance, "
       "scales outside the 95 % CI). Channels whose only findings are spikes, steps or lines "
       "are evaluated on the whole record (no WV parameter was fitted).\n\n";
  if (!figures.empty()) {
    r << "## Figures\n\n";
    for (const auto& f : figures) r << "![" << f << "](" << f << ")\n\n";
  }
  return r.str();
}

std::vector<std::string> diagnosisFigures(
    const Diagnosis& d, const std::function<std::string(const std::string&)>& path_for) {
  std::vector<std::string> names;
  // Overview: measured WV vs simulated envelope per channel.
  {
    plot::Figure fig;
    fig.title = "Measured WV vs simulations of the model (red: family-wise significant misfit)";
    fig.rows = 2;
    fig.cols = 3;
    fig.width = 1800;
    fig.height = 1000;
    for (const auto& c : d.channels) {
      plot::Axes ax;
      ax.title = c.name + (c.adequate ? " — adequate" : " — inadequate");
      ax.xlabel = "tau [s]";
      ax.ylabel = "WV [(" + channelUnit(c.name) + ")^2]";
      ax.logx = ax.logy = true;
      plot::Band env{"simulated envelope", {}, {}, {}, plot::palette(0), 0.25};
      plot::Band ci{"model 95 % CI", {}, {}, {}, plot::palette(1), 0.15};
      plot::Series meas{"measured", {}, {}, {0, 0, 0}};
      plot::Series model{"model", {}, {}, plot::palette(1), plot::LineStyle::Dashed};
      plot::Series bad{"significant", {}, {}, {213, 94, 0}, plot::LineStyle::None,
                       plot::Marker::FilledCircle};
      for (const auto& s : c.scales) {
        if (std::isfinite(s.env_low) && s.env_low > 0) {
          env.x.push_back(s.tau_s);
          env.lo.push_back(s.env_low);
          env.hi.push_back(s.env_high);
        }
        if (s.ci_low > 0) {
          ci.x.push_back(s.tau_s);
          ci.lo.push_back(s.ci_low);
          ci.hi.push_back(s.ci_high);
        }
        if (s.measured > 0) {
          meas.x.push_back(s.tau_s);
          meas.y.push_back(s.measured);
        }
        if (s.model > 0) {
          model.x.push_back(s.tau_s);
          model.y.push_back(s.model);
        }
        if (s.significant && s.measured > 0) {
          bad.x.push_back(s.tau_s);
          bad.y.push_back(s.measured);
        }
      }
      if (!env.x.empty()) ax.bands.push_back(env);
      if (!ci.x.empty()) ax.bands.push_back(ci);
      if (!model.x.empty()) ax.series.push_back(model);
      ax.series.push_back(meas);
      if (!bad.x.empty()) ax.series.push_back(bad);
      fig.axes.push_back(ax);
    }
    fig.rows = static_cast<int>((fig.axes.size() + 2) / 3);
    if (fig.axes.size() < 3) fig.cols = static_cast<int>(fig.axes.size());
    plot::savePng(fig, path_for(std::string("wv_envelope.png")));
    names.push_back("wv_envelope.png");
  }
  if (d.navigation && !d.navigation->t_s.empty()) {
    const NavGain& g = *d.navigation;
    plot::Figure fig;
    fig.width = 1400;
    fig.height = 1000;
    fig.rows = 2;
    fig.title = "Navigation error with measured IMU errors: model before vs extended (RMS over " +
                std::to_string(g.runs) + " runs)";
    for (int panel = 0; panel < 2; ++panel) {
      plot::Axes ax;
      ax.xlabel = "time [s]";
      ax.ylabel = panel == 0 ? "horizontal error [m]" : "vertical error [m]";
      for (const auto& o : g.outages)
        ax.spans.push_back({&o == &g.outages.front() ? "GNSS outage" : "", o.start_s,
                            o.start_s + o.duration_s});
      plot::Series b{"model before", g.t_s, panel == 0 ? g.rms_h_before : g.rms_v_before,
                     plot::palette(1)};
      plot::Series a{"extended model", g.t_s, panel == 0 ? g.rms_h_after : g.rms_v_after,
                     plot::palette(2)};
      ax.series = {b, a};
      if (panel == 0) {
        plot::Series sb{"predicted 1σ before", g.t_s, g.sig_h_before, plot::palette(1),
                        plot::LineStyle::Dashed};
        plot::Series sa{"predicted 1σ after", g.t_s, g.sig_h_after, plot::palette(2),
                        plot::LineStyle::Dashed};
        ax.series.push_back(sb);
        ax.series.push_back(sa);
      }
      fig.axes.push_back(ax);
    }
    plot::savePng(fig, path_for(std::string("navigation_error.png")));
    names.push_back("navigation_error.png");
  }
  for (const auto& c : d.channels) {
    if (c.adequate) continue;
    // Extended model's fit on the cleaned record, with components.
    {
      plot::Figure fig;
      fig.width = 1200;
      fig.height = 800;
      fig.title = c.name + ": extended model vs cleaned record";
      plot::Axes ax;
      ax.xlabel = "tau [s]";
      ax.ylabel = "WV [(" + channelUnit(c.name) + ")^2]";
      ax.logx = ax.logy = true;
      plot::Band ci{"extended model 95 % CI", {}, {}, {}, plot::palette(2), 0.2};
      plot::Series meas{"measured (cleaned)", {}, {}, {0, 0, 0}};
      plot::Series before{"model before", {}, {}, plot::palette(1), plot::LineStyle::Dashed};
      plot::Series after{"model after", {}, {}, plot::palette(2)};
      Eigen::VectorXd tau(static_cast<Eigen::Index>(c.scales_after.size()));
      for (std::size_t j = 0; j < c.scales_after.size(); ++j) {
        const auto& s = c.scales_after[j];
        tau(static_cast<Eigen::Index>(j)) = std::round(s.tau_s * d.rate_hz);  // 2^j samples
        if (s.ci_low > 0) {
          ci.x.push_back(s.tau_s);
          ci.lo.push_back(s.ci_low);
          ci.hi.push_back(s.ci_high);
        }
        if (s.measured > 0) {
          meas.x.push_back(s.tau_s);
          meas.y.push_back(s.measured);
        }
        if (s.model > 0) {
          after.x.push_back(s.tau_s);
          after.y.push_back(s.model);
        }
        if (c.scales[j].model > 0) {
          before.x.push_back(s.tau_s);
          before.y.push_back(c.scales[j].model);
        }
      }
      if (!ci.x.empty()) ax.bands.push_back(ci);
      ax.series.push_back(meas);
      if (!before.x.empty()) ax.series.push_back(before);
      if (!after.x.empty()) ax.series.push_back(after);
      if (!c.model_after.empty()) {
        const Eigen::MatrixXd comp = stochastic::haarWvTerms(c.model_after, tau);
        for (Eigen::Index t = 0; t < comp.cols(); ++t) {
          if (c.model_after.terms[t].kind == stochastic::ProcessKind::SIN) continue;
          plot::Series s{stochastic::formatTerms({c.model_after.terms[t]}, 3), {}, {},
                         plot::palette(static_cast<int>(t) + 3), plot::LineStyle::Dotted};
          s.width = 1.5;
          for (Eigen::Index j = 0; j < comp.rows(); ++j)
            if (comp(j, t) > 0) {
              s.x.push_back(tau(j) / d.rate_hz);
              s.y.push_back(comp(j, t));
            }
          if (!s.x.empty()) ax.series.push_back(s);
        }
      }
      fig.axes.push_back(ax);
      const std::string name = "wv_fit_" + c.name + ".png";
      plot::savePng(fig, path_for(name));
      names.push_back(name);
    }
    if (!c.line_freqs_hz.empty() && !c.spectrum.psd.empty()) {
      plot::Figure fig;
      fig.width = 1200;
      fig.height = 700;
      fig.title = c.name + ": periodogram, lines beyond the family-wise threshold";
      plot::Axes ax;
      ax.xlabel = "frequency [Hz]";
      ax.ylabel = "PSD [(" + channelUnit(c.name) + ")^2/Hz]";
      ax.logx = ax.logy = true;
      plot::Series psd{"measured PSD", {}, {}, {0, 0, 0}};
      psd.width = 1.0;
      plot::Series bg{"background max(model, local level)", {}, {}, plot::palette(1)};
      plot::Series th{"line threshold", {}, {}, {213, 94, 0}, plot::LineStyle::Dashed};
      for (std::size_t k = 1; k < c.spectrum.psd.size(); ++k) {
        if (!(c.spectrum.psd[k] > 0)) continue;
        psd.x.push_back(c.spectrum.freq_hz[k]);
        psd.y.push_back(c.spectrum.psd[k]);
        if (c.spectrum.background.size() == c.spectrum.psd.size() && c.spectrum.background[k] > 0) {
          bg.x.push_back(c.spectrum.freq_hz[k]);
          bg.y.push_back(c.spectrum.background[k]);
          th.x.push_back(c.spectrum.freq_hz[k]);
          th.y.push_back(c.spectrum.background[k] * c.spectrum.threshold_ratio);
        }
      }
      ax.series = {psd, bg, th};
      fig.axes.push_back(ax);
      const std::string name = "spectrum_" + c.name + ".png";
      plot::savePng(fig, path_for(name));
      names.push_back(name);
    }
  }
  return names;
}

}  // namespace navimpact::report
