// diagnosis.json, report.md and figures of navimpact diagnose.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include <nlohmann/json.hpp>

#include "navimpact/analysis/diagnosis.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/plot/figure.hpp"
#include "navimpact/report/diagnosis_report.hpp"
#include "navimpact/report/timing.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"
#include "figures.hpp"

namespace navimpact::report {

using namespace analysis;

namespace {

/// An undecided finding's name: "undecided between A and B", or where the
/// runner-up is the same cause alone (the winner has another term beside it:
/// "undecided between random_walk and random_walk" before) "A, with or
/// without the other terms found".
std::string undecidedText(const std::string& shown, const std::string& cause, const std::string& runner_up) {
  if (runner_up == cause) return shown + ", undecided: with or without the other terms found";
  return "undecided between " + shown + " and " + runner_up;
}

using nlohmann::json;

json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

/// Add (x, y) to a series of a log axis when y > 0 (a non-positive value has no place on it).
void addPositive(plot::Series& s, double x, double y) {
  if (!(y > 0)) return;
  s.x.push_back(x);
  s.y.push_back(y);
}

/// Add (x, lo..hi) to a band of a log axis when lo > 0.
void addPositive(plot::Band& b, double x, double lo, double hi) {
  if (!(lo > 0)) return;
  b.x.push_back(x);
  b.lo.push_back(lo);
  b.hi.push_back(hi);
}

json findingJson(const Finding& f) {
  json j;
  j["channel"] = f.channel;
  j["cause"] = causeName(f.cause);
  json p = json::object();
  for (const auto& kv : f.params) p[kv.first] = num(kv.second);
  if (f.cause == Cause::Outliers) p["times_s"] = f.times_s;
  j["params"] = p;
  // A range only where there is one (a finding that explains no scale outside
  // the CI has no scales_s).
  if (std::isfinite(f.range_lo) && std::isfinite(f.range_hi)) j[f.range_key] = {f.range_lo, f.range_hi};
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
  j["decided"] = f.decided;
  if (!f.runner_up.empty()) {
    j["runner_up"] = f.runner_up;
    j["runner_up_detail"] = f.runner_up_detail;
    j["aic_margin"] = num(f.aic_margin);
    if (f.runner_up_draws > 0) {
      j["runner_up_p"] = num(f.runner_up_p);
      j["runner_up_draws"] = f.runner_up_draws;
    }
  }
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
      {"cause_selection", "gamma-deviance WV fit of each family on the whole cleaned record, AIC; level shifts against the best stochastic extension by a penalised multi-scale contrast likelihood"},
      {"extension", "GMWM refit of the extended structure warm-started at the user's "
                    "parameters plus the findings (first half for the gain, whole record for "
                    "the model file), kept when it does not raise the deviance"},
      {"gain", "held-out second half (first-half fit) when a process was fitted; one-sided paired z test over scales; significant only when deviance and objective improved and p < 0.05"}};
  json chans = json::array();
  for (const auto& c : d.channels) {
    json cj;
    cj["name"] = c.name;
    cj["verdict"] = c.adequate ? "adequate" : "inadequate";
    json fs = json::array();
    for (const auto& f : c.findings) fs.push_back(findingJson(f));
    cj["findings"] = fs;
    if (c.unexplained.scales > 0)
      cj["unexplained_misfit"] = {{"scales", c.unexplained.scales},
                                  {"scales_s", {num(c.unexplained.tau_lo_s), num(c.unexplained.tau_hi_s)}},
                                  {"ratio", num(c.unexplained.ratio)}};
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
    j["navigation"] = nav;
  }
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

namespace {

/// Parameter with its unit and 95 % interval, e.g. "T = 0.0223 s (0.019–0.027)".
std::string paramText(const Finding& f, const std::string& key, double v) {
  const std::string unit = channelUnit(f.channel);
  std::string u;
  if (key == "T" || key == "t_s") u = " s";
  else if (key == "freq_hz") u = " Hz";
  else if (key == "omega") u = " " + unit + "/sample";
  else if (key != "count") u = " " + unit;
  std::string name = key == "t_s" ? "t" : key == "freq_hz" ? "f" : key;
  std::string s = name + " = " + formatNumber(v, key == "t_s" || key == "freq_hz" ? 6 : 3);
  if (v == 0 && f.direction == "overstated") return s + u + " (none in the data)";  // a model term retuned to zero
  for (const auto& kv : f.intervals)
    if (kv.first == key) {
      const std::string lo = formatNumber(kv.second.first, 2), hi = formatNumber(kv.second.second, 2);
      if (lo == hi) s += " ± " + formatNumber(0.5 * (kv.second.second - kv.second.first), 1);
      else s += " (" + lo + "–" + hi + ")";
    }
  return s + u;
}

std::string shortAction(const Finding& f) {
  // a model term whose best fit is zero: the data show none of it
  if (f.direction == "overstated" && !f.params.empty() && f.params.front().second == 0) return "remove the term";
  switch (f.cause) {
    case Cause::WhiteNoise:
    case Cause::QuantizationNoise: return f.direction == "overstated" ? "lower it in the model" : "raise it in the model";
    case Cause::RandomWalk:
    case Cause::Drift:
    case Cause::GaussMarkov: return f.direction == "overstated" ? "retune the term" : "add the term";
    case Cause::Sinusoid: return "add SIN terms or notch it";
    case Cause::LevelShift: return "segment the record there";
    case Cause::Outliers: return "remove before fitting";
  }
  return "";
}

std::string strength(double p) {
  if (!(p >= 0)) return "—";
  if (p < 1e-12) return "p < 1e-12";
  return "p = " + formatNumber(p, 2);
}

}  // namespace

std::string diagnosisReport(const Diagnosis& d, const std::vector<std::string>& figures) {
  std::ostringstream r;
  r << "# IMU error model diagnosis\n\n";
  r << "`" << d.source << "`: " << d.samples << " samples at " << formatNumber(d.rate_hz, 6) << " Hz ("
    << formatNumber(d.samples / d.rate_hz, 5) << " s); model `" << d.model_before.source << "`.\n\n";
  int bad = 0, nf = 0;
  for (const auto& c : d.channels) {
    bad += c.adequate ? 0 : 1;
    nf += static_cast<int>(c.findings.size());
  }
  r << "**Verdict: " << (d.adequate ? "adequate" : "inadequate") << "**";
  if (d.adequate)
    r << " — every channel is consistent with simulations of the model (outliers, spectral lines, level "
         "shifts, wavelet variance; family-wise false-alarm level "
      << formatNumber(d.options.alpha * 100, 3) << " % for the whole record).\n\n";
  else
    r << " — " << bad << " of " << d.channels.size() << " channels, " << nf
      << " finding(s) (family-wise level " << formatNumber(d.options.alpha * 100, 3) << " %).\n\n";
  for (const auto& n : d.notices) r << "> " << n << "\n\n";
  if (!d.adequate) {
    // One row per channel and cause (several lines or shifts of a channel share it).
    r << "| channel | cause | parameters (95 % interval) | evidence | what to do |\n|---|---|---|---|---|\n";
    for (const auto& c : d.channels) {
      std::vector<bool> done(c.findings.size(), false);
      for (std::size_t i = 0; i < c.findings.size(); ++i) {
        if (done[i]) continue;
        const Finding& f0 = c.findings[i];
        std::string ps, cause = causeName(f0.cause);
        double pmin = f0.p_value;
        std::vector<int> events;
        int count = 0;
        for (std::size_t k = i; k < c.findings.size(); ++k) {
          const Finding& f = c.findings[k];
          if (done[k] || f.cause != f0.cause || f.direction != f0.direction || f.decided != f0.decided ||
              f.runner_up != f0.runner_up)
            continue;
          done[k] = true;
          ++count;
          pmin = std::min(pmin, f.p_value);
          if (f.event >= 0) events.push_back(f.event + 1);
          std::string one;
          for (const auto& kv : f.params) {
            if (f.cause == Cause::Outliers && kv.first == "count") {
              one = formatNumber(kv.second, 4) + " event(s)";
              if (!f.times_s.empty()) {
                one += " at t = " + formatNumber(f.times_s[0], 6);
                for (std::size_t q = 1; q < std::min<std::size_t>(3, f.times_s.size()); ++q) one += ", " + formatNumber(f.times_s[q], 6);
                one += f.times_s.size() > 3 ? ", … s" : " s";
              }
              continue;
            }
            one += (one.empty() ? "" : ", ") + paramText(f, kv.first, kv.second);
          }
          if (!f.harmonics_hz.empty()) one += ", " + std::to_string(f.harmonics_hz.size()) + " harmonic(s)";
          ps += (ps.empty() ? "" : "; ") + one;
        }
        if (count > 1) cause = std::to_string(count) + " × " + cause;
        if (f0.direction == "overstated") cause += " (overstated)";
        if (!f0.decided) cause = undecidedText(cause, causeName(f0.cause), f0.runner_up);
        if (!events.empty()) {
          cause += " [event";
          for (int e : events) cause += " " + std::to_string(e);
          cause += "]";
        }
        r << "| " << c.name << " | " << cause << " | " << ps << " | " << strength(pmin) << " | " << shortAction(f0) << " |\n";
      }
      if (const auto& u = c.unexplained; u.scales > 0) {
        const double f = u.ratio >= 1 ? u.ratio : 1.0 / u.ratio;
        r << "| " << c.name << " | unexplained misfit | measured WV " << formatNumber(f, 3) << "x "
          << (u.ratio >= 1 ? "above" : "below") << " the " << (c.findings.empty() ? "model" : "extended model")
          << " at tau = " << formatNumber(u.tau_lo_s, 3) << "–" << formatNumber(u.tau_hi_s, 3) << " s (" << u.scales
          << " scale(s) rejected family-wise, each a factor 2 or a CI width off) | no cause of the catalogue "
             "reduces it | "
          << (c.findings.empty() ? std::string("check the model's terms and units against the record") +
                                       (u.ratio < 1 ? " (a term overstates the noise)" : "")
                                 : std::string("the extension leaves it: read the scale table below before relying on it"))
          << " |\n";
      }
    }
    r << "\n";
  }
  if (!d.events.empty()) {
    r << "**Events on several channels** (each is one event, listed above under every channel it touches):\n\n";
    for (std::size_t i = 0; i < d.events.size(); ++i) {
      const auto& e = d.events[i];
      r << i + 1 << ". t = " << formatNumber(e.t_s, 6) << " s";
      if (e.duration_s > 0) r << " (" << formatNumber(e.duration_s, 2) << " s)";
      r << ": " << causeName(e.cause) << " on";
      for (const auto& ch : e.channels) r << " " << ch;
      r << "\n";
    }
    r << "\n";
  }
  {
    r << "**Gain of the extended model** (held-out second half unless stated; significant = both "
         "criteria better and the paired test rejects at 5 %):\n\n"
         "| channel | WV objective before → after | deviance before → after | test | result |\n"
         "|---|---|---|---|---|\n";
    for (const auto& c : d.channels) {
      if (c.adequate) continue;
      const auto& g = c.gain;
      r << "| " << c.name << " | " << formatNumber(g.objective_before, 4) << " → " << formatNumber(g.objective_after, 4) << " | "
        << formatNumber(g.deviance_before, 4) << " → " << formatNumber(g.deviance_after, 4) << " | z = " << formatNumber(g.z, 3)
        << ", p = " << formatNumber(g.p_value, 2) << (g.basis == "second_half" ? "" : " (whole record)") << " | "
        << (g.significant ? "significant, better" : "not significant, " + g.direction) << " |\n";
    }
    r << "\n";
  }
  if (d.navigation) {
    const NavGain& g = *d.navigation;
    for (const auto& o : g.outages)
      r << "**Navigation** (" << g.runs << " paired runs, outage " << formatNumber(o.start_s, 5) << " s + "
        << formatNumber(o.duration_s, 4) << " s): horizontal error at the end " << formatNumber(o.mean_h_before, 3) << " → "
        << formatNumber(o.mean_h_after, 3) << " m, position ANEES " << formatNumber(o.anees_before, 3) << " → "
        << formatNumber(o.anees_after, 3) << " (band " << formatNumber(o.nees_band.first, 3) << "–"
        << formatNumber(o.nees_band.second, 3) << "); extension better in " << o.wins << " of " << g.runs << " runs: "
        << (o.significant ? "significant" : "not significant") << " (sign test p = " << formatNumber(o.sign_p, 2)
        << ").\n\n";
  }
  r << "The extended model is in `model_extended.yaml`; the evidence follows below.\n\n";
  r << "---\n\n# Evidence\n\n";
  for (const auto& c : d.channels) {
    if (c.findings.empty() && c.notes.empty()) continue;
    r << "## " << c.name << "\n\n`" << modelText(c.model_before) << "` → `" << modelText(c.model_after) << "`\n\n";
    for (const auto& f : c.findings) {
      r << "- **" << (f.decided ? std::string(causeName(f.cause))
                                : undecidedText(causeName(f.cause), causeName(f.cause), f.runner_up))
        << "**: " << f.explanation;
      if (!f.evidence.empty()) r << " *Evidence:* " << f.evidence << ".";
      if (!f.decided) {
        r << " *Undecided:* the runner-up, " << f.runner_up_detail << ", ";
        if (f.runner_up_draws > 0)
          r << "stays plausible at 5 % (parametric bootstrap).";
        else if (f.aic_margin >= 0)
          r << "is only " << formatNumber(f.aic_margin, 3) << " above it in AIC (decided from a margin of 2).";
        else
          r << "is " << formatNumber(-f.aic_margin, 3) << " below it in AIC"
            << (f.runner_up == "level_shift" ? ", but the level-shift test did not reject the record's stochastic explanation at its family-wise level."
                                             : ".");
      }
      r << " *What to do:* " << f.action << ".\n";
    }
    for (const auto& n : c.notes) r << "- Note: " << n << ".\n";
    r << "- Gain: " << c.gain.test << "; " << c.gain.outside_before << " → " << c.gain.outside_after << " of "
      << c.gain.scales << " scales outside the 95 % CI.\n";
    if (!c.refit_full.empty()) r << "- GMWM refit: whole record " << c.refit_full << "; first half " << c.refit_half << ".\n";
    bool any = false;
    for (const auto& s : c.scales) any = any || s.outside95;
    if (any) {
      // The table is the raw record against the model before; the findings
      // describe the cleaned record (outliers, shifts and lines taken out).
      // Where cleaning changed the WV, its column stands beside the raw one so
      // that a finding's "N scales outside the 95 % CI" can be read here.
      bool cleaned = c.wv_cleaned.size() == c.scales.size();
      bool differs = false;
      for (std::size_t j = 0; cleaned && j < c.scales.size(); ++j)
        differs = differs || std::abs(c.wv_cleaned[j] - c.scales[j].measured) > 1e-9 * std::abs(c.scales[j].measured);
      cleaned = cleaned && differs;
      if (cleaned)
        r << "\nScales where the raw record leaves the model's 95 % CI; the findings above are on the cleaned "
             "record (its WV beside the raw one).\n";
      r << "\n| tau [s] | measured WV" << (cleaned ? " (raw) | cleaned WV" : "") << " | model WV | 95 % CI | ratio"
        << (cleaned ? " (raw)" : "") << " | significant |\n|---|---|" << (cleaned ? "---|" : "") << "---|---|---|---|\n";
      for (std::size_t j = 0; j < c.scales.size(); ++j) {
        const auto& s = c.scales[j];
        if (!s.outside95) continue;
        r << "| " << formatNumber(s.tau_s, 4) << " | " << formatNumber(s.measured, 3) << " | ";
        if (cleaned) r << formatNumber(c.wv_cleaned[j], 3) << " | ";
        r << formatNumber(s.model, 3) << " | " << formatNumber(s.ci_low, 3) << "–" << formatNumber(s.ci_high, 3) << " | "
          << formatNumber(s.ratio, 3) << " | " << (s.significant ? "yes" : "no") << " |\n";
      }
    }
    r << "\n";
  }
  if (d.navigation) {
    const NavGain& g = *d.navigation;
    r << "## Navigation gain\n\nAlong `" << g.trajectory << "` with the **measured** errors as the truth: " << g.truth
      << ". The filter ran with the model before and with " << g.filter_after << ", on the same " << g.runs
      << " realisations (seed " << g.seed << "). " << g.settings << "."
      << (g.filter_note.empty() ? std::string() : " Note: " + g.filter_note + ".") << "\n\n"
      << "| outage | horizontal error at end [m] | vertical [m] | max horizontal drift [m] | position ANEES (95 % band) | runs better | sign test p | paired t p |\n"
         "|---|---|---|---|---|---|---|---|\n";
    for (const auto& o : g.outages)
      r << "| " << formatNumber(o.start_s, 5) << " s + " << formatNumber(o.duration_s, 4) << " s | " << formatNumber(o.mean_h_before, 3)
        << " → " << formatNumber(o.mean_h_after, 3) << " | " << formatNumber(o.mean_v_before, 3) << " → " << formatNumber(o.mean_v_after, 3)
        << " | " << formatNumber(o.mean_drift_before, 3) << " → " << formatNumber(o.mean_drift_after, 3) << " | "
        << formatNumber(o.anees_before, 3) << " → " << formatNumber(o.anees_after, 3) << " (" << formatNumber(o.nees_band.first, 3) << "–"
        << formatNumber(o.nees_band.second, 3) << ") | " << o.wins << " of " << g.runs << " | " << formatNumber(o.sign_p, 2) << " | "
        << formatNumber(o.t_p, 2) << " |\n";
    r << "\nA navigation gain is significant only when the extension gives the smaller horizontal error at the outage "
         "end in significantly more runs than chance (exact sign test, p < 0.05); the runs share one recording.\n\n";
  }
  r << "## Method\n\n"
       "- **Outliers:** second difference beyond a Bonferroni threshold (scale: the larger of the model's and the "
       "robust MAD); exceedances closer than 10 samples, and level changes that undo each other within 1 s, are one "
       "event (a knock). Interpolated out.\n"
       "- **Spectral lines:** Hann periodogram of the whole record against max(model PSD, the record's local "
       "level), Bonferroni over all bins from 4 cycles per record to Nyquist; harmonics and a wandering frequency "
       "are one finding. Subtracted.\n"
       "- **Level shifts:** window contrasts scaled by the model's Haar WV (valid under random walks and "
       "Gauss-Markov noise); each kept only when significant against the best stochastic explanation without shifts "
       "(exact likelihood ratio of block means, chi2_1 at a fixed time, Bonferroni over the block boundaries).\n"
       "- **Wavelet variance:** measured Haar WV of the cleaned record against the model's, chi-square CI "
       "(dof lowered to what "
    << d.options.simulations << " simulations of the model show, seed " << d.options.seed
    << "), Bonferroni over scales; each process family (or a retuned term), and each pair fitted jointly, fitted "
       "to the excess by the chi-square deviance, chosen by AIC on the whole record (runner-up given as evidence); "
       "no term below one CI width, no GM with T beyond a fifth of the record. A finding whose runner-up naming "
       "another cause is within 2 in AIC is \"undecided between\" the two.\n"
       "- **Slow explanations** (random walk, drift, Gauss-Markov with T near the record; one or two): each fitted "
       "on the exact likelihood of block means and chosen by AIC, a pair only when a single term, simulated, gives "
       "its lead in at most 1 % of records; decided only when a parametric bootstrap rejects the runner-up at 5 % "
       "(the runner-up, simulated, rarely gives the winner such a lead; or, for a larger set containing the winner, "
       "the winner, simulated, often gives it its lead); also compared with a single level shift.\n"
       "- **Gain:** the first-half extension against the model on the held-out second half; one-sided paired z "
       "test over the scales of the per-scale deviance.\n"
       "- The family-wise level is split WV 40 %, lines 20 %, level shifts 20 %, outliers 20 %, each over the "
       "channels.\n\n";
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
    plot::Figure fig = detail::figureOf(
        1800, 1000, "Measured WV vs simulations of the model (red: family-wise significant misfit)", 2, 3);
    for (const auto& c : d.channels) {
      plot::Axes ax = detail::logLogAxes("tau [s]", "WV [(" + channelUnit(c.name) + ")^2]");
      ax.title = c.name + (c.adequate ? " — adequate" : " — inadequate");
      plot::Band env{"simulated envelope", {}, {}, {}, plot::palette(0), 0.25};
      plot::Band ci{"model 95 % CI", {}, {}, {}, plot::palette(1), 0.15};
      plot::Series meas{"measured", {}, {}, {0, 0, 0}};
      plot::Series model{"model", {}, {}, plot::palette(1), plot::LineStyle::Dashed};
      plot::Series bad{"significant", {}, {}, {213, 94, 0}, plot::LineStyle::None,
                       plot::Marker::FilledCircle};
      for (const auto& s : c.scales) {
        if (std::isfinite(s.env_low)) addPositive(env, s.tau_s, s.env_low, s.env_high);
        addPositive(ci, s.tau_s, s.ci_low, s.ci_high);
        addPositive(meas, s.tau_s, s.measured);
        addPositive(model, s.tau_s, s.model);
        if (s.significant) addPositive(bad, s.tau_s, s.measured);
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
      plot::Figure fig = detail::figureOf(1200, 800, c.name + ": extended model vs cleaned record");
      plot::Axes ax = detail::logLogAxes("tau [s]", "WV [(" + channelUnit(c.name) + ")^2]");
      plot::Band ci{"extended model 95 % CI", {}, {}, {}, plot::palette(2), 0.2};
      plot::Series meas{"measured (cleaned)", {}, {}, {0, 0, 0}};
      plot::Series before{"model before", {}, {}, plot::palette(1), plot::LineStyle::Dashed};
      plot::Series after{"model after", {}, {}, plot::palette(2)};
      Eigen::VectorXd tau(static_cast<Eigen::Index>(c.scales_after.size()));
      for (std::size_t j = 0; j < c.scales_after.size(); ++j) {
        const auto& s = c.scales_after[j];
        tau(static_cast<Eigen::Index>(j)) = std::round(s.tau_s * d.rate_hz);  // 2^j samples
        addPositive(ci, s.tau_s, s.ci_low, s.ci_high);
        addPositive(meas, s.tau_s, s.measured);
        addPositive(after, s.tau_s, s.model);
        addPositive(before, s.tau_s, c.scales[j].model);
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
          for (Eigen::Index j = 0; j < comp.rows(); ++j) addPositive(s, tau(j) / d.rate_hz, comp(j, t));
          if (!s.x.empty()) ax.series.push_back(s);
        }
      }
      fig.axes.push_back(ax);
      const std::string name = "wv_fit_" + c.name + ".png";
      plot::savePng(fig, path_for(name));
      names.push_back(name);
    }
    if (!c.line_freqs_hz.empty() && !c.spectrum.psd.empty()) {
      plot::Figure fig = detail::figureOf(1200, 700, c.name + ": periodogram, lines beyond the family-wise threshold");
      plot::Axes ax = detail::logLogAxes("frequency [Hz]", "PSD [(" + channelUnit(c.name) + ")^2/Hz]");
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

std::size_t writeDiagnosisOutputs(const Diagnosis& d, const std::string& input_json,
                                  const std::string& model_comment, OutputSet& out) {
  const auto figs = diagnosisFigures(d, [&out](const std::string& n) { return out.stage(n).string(); });
  out.writeText("diagnosis.json", diagnosisJson(d, input_json));
  out.writeText("report.md", diagnosisReport(d, figs));
  out.writeText("model_extended.yaml", stochastic::toYaml(d.model_after, model_comment));
  // wall-clock figures apart, so that two identical runs give identical result files
  nlohmann::json timing = {{"diagnosis_wall_s", d.wall_s}};
  if (d.navigation) timing["navigation_wall_s"] = d.navigation->wall_s;
  writeTiming(out, timing);
  return figs.size();
}

std::string diagnosisSummary(const Diagnosis& d) {
  std::ostringstream os;
  os << "verdict: " << (d.adequate ? "adequate" : "inadequate") << "\n";
  for (const auto& c : d.channels) {
    os << "  " << c.name << ": " << (c.adequate ? "adequate" : "inadequate");
    for (const auto& f : c.findings) os << " " << causeName(f.cause);
    if (c.unexplained.scales > 0) os << " unexplained_misfit";
    if (!c.adequate)
      os << "  (scales outside CI " << c.gain.outside_before << " -> " << c.gain.outside_after << ", "
         << c.gain.basis << ", gain " << (c.gain.significant ? "significant" : "not significant") << ")";
    os << "\n";
  }
  if (d.navigation)
    for (const auto& g : d.navigation->outages)
      os << "  navigation, outage " << g.start_s << " s + " << g.duration_s << " s: horizontal error at end "
         << g.mean_h_before << " -> " << g.mean_h_after << " m (mean of " << d.navigation->runs
         << " runs; after better in " << g.wins << "; " << (g.significant ? "significant" : "not significant")
         << ", sign test p = " << g.sign_p << ")\n";
  return os.str();
}

}  // namespace navimpact::report
