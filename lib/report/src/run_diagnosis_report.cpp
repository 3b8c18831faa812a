// Outputs of navimpact diagnose --run: run_diagnosis.json, report.md, figure.
#include "navimpact/report/run_diagnosis_report.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "navimpact/core/format.hpp"
#include "navimpact/plot/figure.hpp"
#include "navimpact/report/timing.hpp"
#include "navimpact/stochastic/model_file.hpp"

namespace navimpact::report {

using analysis::RunDiagnosis;

namespace {

nlohmann::json num(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

std::string r3(double x) { return formatReadable(x, 3); }

}  // namespace

std::string runDiagnosisJson(const RunDiagnosis& d, const std::string& input_json) {
  nlohmann::json j;
  j["input"] = nlohmann::json::parse(input_json);
  j["verdict"] = d.verdict;
  j["verdict_test"] = {
      {"family_false_alarm_rate", d.alpha},
      {"tests", d.tests},
      {"level_per_test", d.test_level},
      {"method",
       "Bonferroni over two-sided tests of the run-level statistics (RMS outage-end error per quantity and duration, "
       "mean position NEES per duration) against their distribution over the simulated realisations "
       "(ln statistic, Student t prediction interval with R - 1 dof)"},
      {"resolution_factor", d.resolution_factor},
      {"resolvable_factor", analysis::kResolvableFactor},
      {"reasons", d.reasons}};
  auto findingJson = [](const analysis::RunFinding& f) {
    nlohmann::json p = nlohmann::json::object(), iv = nlohmann::json::object();
    for (const auto& kv : f.params) p[kv.first] = num(kv.second);
    for (const auto& kv : f.interval) iv[kv.first] = {num(kv.second.first), num(kv.second.second)};
    return nlohmann::json{{"cause", f.cause}, {"channel", f.channel}, {"params", p}, {"interval", iv}, {"note", f.note}};
  };
  j["findings"] = nlohmann::json::array();
  for (const auto& f : d.findings) j["findings"].push_back(findingJson(f));
  auto gainJson = [&](const analysis::CauseResult& c) {
    return nlohmann::json{{"cause", c.cause},
                          {"outage_error_before_m", num(c.error_before_m)},
                          {"outage_error_after_m", num(c.error_after_m)},
                          {"vertical_error_before_m", num(c.vertical_before_m)},
                          {"vertical_error_after_m", num(c.vertical_after_m)},
                          {"anees_before", num(c.anees_before)},
                          {"anees_after", num(c.anees_after)},
                          {"nll_gain", num(c.gain)},
                          {"p_value", num(c.p_value)},
                          {"error_p_value", num(c.error_p_value)},
                          {"heldout_outages", c.heldout_outages},
                          {"significant", c.significant},
                          {"extension", c.extension}};
  };
  if (d.best >= 0) {
    j["gain"] = gainJson(d.causes[static_cast<std::size_t>(d.best)]);
  } else if (!d.causes.empty()) {
    j["gain"] = gainJson(d.causes.front());
    const auto& b = d.causes.front();
    j["gain"]["note"] = b.significant && !b.given.empty()
                            ? "undecided between " + b.cause + " and " + b.given + ": the best-ranked cause gains nothing "
                              "significant on top of the runner-up's extension; no extension written"
                            : "no cause has a significant held-out gain: the best-ranked one is shown, no extension written";
  } else {
    j["gain"] = {{"outage_error_before_m", nullptr}, {"outage_error_after_m", nullptr}, {"anees_before", nullptr},
                 {"anees_after", nullptr}, {"significant", false}, {"note", "causes not analysed"}};
  }
  nlohmann::json cs = nlohmann::json::array();
  for (std::size_t k = 0; k < d.causes.size(); ++k) {
    const auto& c = d.causes[k];
    nlohmann::json cj = gainJson(c);
    // the top-ranked cause was added to the runner-up's extension, every
    // other one to the top cause's
    if (!c.given.empty()) {
      const bool top = k == 0;
      cj[top ? "on_top_of_runner_up" : "on_top_of_best"] = {{top ? "runner_up_cause" : "best_cause", c.given},
                                                            {"nll_gain", num(c.gain_given)},
                                                            {"p_value", num(c.p_given)},
                                                            {"named", c.adds}};
    }
    cj["findings"] = nlohmann::json::array();
    for (const auto& f : c.findings) cj["findings"].push_back(findingJson(f));
    cs.push_back(cj);
  }
  j["causes"] = cs;
  j["cross_validation"] = {{"folds", d.folds},
                           {"method",
                            "time blocks of the run; each outage held out once, the cause fitted outside its block; "
                            "score: position negative log-likelihood at the outage end; one-sided paired sign-flip "
                            "permutation test (20000 seeded flips) at alpha / causes"}};
  j["run"] = {{"rawlog", d.rawlog},
              {"model", d.model_source},
              {"imu_rate_hz", d.imu_rate_hz},
              {"aided_from_s", d.aided_from_s},
              {"end_s", d.run_end_s},
              {"reference_sigma_h_m", d.reference.sigma_h_m},
              {"reference_sigma_v_m", d.reference.sigma_v_m},
              {"reference_has_velocity", d.reference.has_velocity},
              {"reference_has_attitude", d.reference.has_attitude}};
  j["simulation"] = {{"errors", d.errors_source},
                     {"trajectory", d.trajectory_source},
                     {"realisations", d.realisations},
                     {"seed", d.seed},
                     {"reconverge_s", d.reconverge_s}};
  nlohmann::json durs = nlohmann::json::array();
  for (const auto& dd : d.durations) {
    nlohmann::json o = nlohmann::json::array();
    for (const auto& s : dd.measured)
      o.push_back({{"start_s", s.start_s},
                   {"end_s", s.end_s},
                   {"horizontal_error_m", s.horizontal_error_m},
                   {"vertical_error_m", s.vertical_error_m},
                   {"horizontal_sigma_m", s.horizontal_sigma_m},
                   {"vertical_sigma_m", s.vertical_sigma_m},
                   {"nees", num(s.nees)}});
    durs.push_back({{"duration_s", dd.duration_s},
                    {"period_s", dd.period_s},
                    {"measured_outages", dd.measured.size()},
                    {"simulated_outages", dd.simulated_outages},
                    {"measured_anees", num(dd.anees)},
                    {"anees_band", {num(dd.anees_lo), num(dd.anees_hi)}},
                    {"anees_outside_band", dd.anees_rejects},
                    {"anees_p_value", num(dd.anees_p)},
                    {"anees_chi2_band_independent_outages", {num(dd.chi2_lo), num(dd.chi2_hi)}},
                    {"predicted_anees", num(dd.predicted_anees)},
                    {"coverage", dd.distribution.coverage},
                    {"coverage_expected", dd.distribution.coverage_expected},
                    {"outages", o}});
  }
  j["durations"] = durs;
  nlohmann::json cmp = nlohmann::json::array();
  for (const auto& c : d.comparisons)
    cmp.push_back({{"quantity", c.quantity},
                   {"unit", c.unit},
                   {"duration_s", c.duration_s},
                   {"measured_count", c.measured.size()},
                   {"predicted_count", c.predicted.size()},
                   {"measured_rms", num(c.measured_rms)},
                   {"predicted_rms", num(c.predicted_rms)},
                   {"predicted_p05", num(c.predicted_p05)},
                   {"predicted_p50", num(c.predicted_p50)},
                   {"predicted_p95", num(c.predicted_p95)},
                   {"ratio", num(c.ratio)},
                   {"ratio_interval", {num(c.ratio_lo), num(c.ratio_hi)}},
                   {"predicted_log_sd", num(c.predicted_log_sd)},
                   {"interval_method", "Student t prediction interval over the realisations, level " +
                                           formatNumber(1.0 - d.test_level, 6)},
                   {"p_value", num(c.p_value)},
                   {"rejects", c.rejects}});
  j["comparisons"] = cmp;
  j["notices"] = d.notices;
  return j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

std::string runDiagnosisMarkdown(const RunDiagnosis& d) {
  std::ostringstream s;
  s << "# Run diagnosis: " << d.rawlog << "\n\n";
  s << "Model: " << d.model_source << ". Simulation: " << d.realisations << " realisations (seed " << d.seed
    << "), IMU errors " << d.errors_source << "; trajectory: " << d.trajectory_source << ".\n\n";
  s << "**Verdict: " << d.verdict << "** (" << d.tests << " tests, each at level " << formatReadable(d.test_level, 3)
    << ", family-wise false-alarm rate at most " << formatNumber(d.alpha) << ").\n\n";
  for (const auto& r : d.reasons) s << "- " << r << "\n";
  if (!d.reasons.empty()) s << "\n";
  s << "## Measured against predicted at the outage ends\n\n";
  s << "Ratio = measured RMS over the run's outages / the same RMS predicted (geometric mean over the "
    << d.realisations << " realisations); interval and p from the spread of that RMS over the realisations "
    << "(Student t prediction interval on ln RMS), level " << formatNumber(1.0 - d.test_level, 4) << ".\n\n";
  s << "| duration [s] | quantity | measured outages | measured RMS | predicted RMS | predicted 5-95 % | ratio | "
       "interval | p |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : d.comparisons)
    s << "| " << formatNumber(c.duration_s) << " | " << c.quantity << " | " << c.measured.size() << " | "
      << r3(c.measured_rms) << " " << c.unit << " | " << r3(c.predicted_rms) << " " << c.unit << " | "
      << r3(c.predicted_p05) << " - " << r3(c.predicted_p95) << " | " << r3(c.ratio) << " | [" << r3(c.ratio_lo)
      << ", " << r3(c.ratio_hi) << "] | " << formatReadable(c.p_value, 2) << (c.rejects ? " (rejects)" : "")
      << " |\n";
  s << "\n## Measured NEES and coverage (the filter's own sigma)\n\n";
  s << "| duration [s] | outages | mean position NEES | simulated band | p | chi-square band (independent outages) | "
       "simulated mean NEES | coverage 1/2/3 sigma |\n|---|---|---|---|---|---|---|---|\n";
  for (const auto& dd : d.durations)
    s << "| " << formatNumber(dd.duration_s) << " | " << dd.measured.size() << " | " << r3(dd.anees) << " | ["
      << r3(dd.anees_lo) << ", " << r3(dd.anees_hi) << "]" << (dd.anees_rejects ? " outside" : "") << " | "
      << formatReadable(dd.anees_p, 2) << " | [" << r3(dd.chi2_lo) << ", " << r3(dd.chi2_hi) << "] | "
      << r3(dd.predicted_anees) << " | " << formatFixed(100 * dd.distribution.coverage[0], 0) << " / "
      << formatFixed(100 * dd.distribution.coverage[1], 0) << " / " << formatFixed(100 * dd.distribution.coverage[2], 0)
      << " % (expected 68 / 95 / 99.7) |\n";
  s << "\nFigure: predicted_vs_measured.png (simulated 5-95 % band and median, measured outages as points).\n";
  s << "\n## Causes (fitted on training outages, scored on held-out ones)\n\n";
  if (d.causes.empty()) {
    s << "Not analysed.\n";
  } else {
    s << d.folds << "-fold cross-validation over time blocks of the run; gain = mean decrease of the position "
      << "negative log-likelihood per held-out outage; p: one-sided paired sign-flip permutation test, significant "
      << "below " << formatReadable(d.alpha / double(d.causes.size()), 3) << ".\n\n";
    s << "| rank | cause | held-out outages | horizontal RMS before / after | vertical RMS before / after | "
         "mean NEES before / after | gain | p | significant |\n|---|---|---|---|---|---|---|---|---|\n";
    for (std::size_t k = 0; k < d.causes.size(); ++k) {
      const auto& c = d.causes[k];
      s << "| " << k + 1 << " | " << c.cause << " | " << c.heldout_outages << " | " << r3(c.error_before_m) << " / "
        << r3(c.error_after_m) << " m | " << r3(c.vertical_before_m) << " / " << r3(c.vertical_after_m) << " m | "
        << r3(c.anees_before) << " / " << r3(c.anees_after) << " | " << r3(c.gain) << " | "
        << formatReadable(c.p_value, 2) << " | " << (c.significant ? "yes" : "no") << " |\n";
    }
    for (std::size_t k = 0; k < d.causes.size(); ++k) {
      const auto& c = d.causes[k];
      if (c.given.empty()) continue;
      s << "\n" << c.cause << " added to the extension of " << c.given << ": held-out gain " << r3(c.gain_given)
        << ", p = " << formatReadable(c.p_given, 2) << " -> ";
      if (k == 0 && c.adds && !(c.gain_given > 0 && c.p_given < d.alpha))
        s << "not significant, but " << c.given << " adds nothing on top of " << c.cause << " (below): " << c.cause
          << " named";
      else if (k == 0 && !c.adds)
        s << "the held-out outages do not tell " << c.cause << " from " << c.given << ": undecided";
      else if (c.adds)
        s << "it explains more than " << c.given << (k == 0 ? "" : ": named");
      else
        s << "nothing beyond " << c.given << " (it shares its signature): not named";
      s << ".\n";
    }
    s << "\n### Fitted parameters (whole run)\n\n| cause | channel | parameter | value | interval |\n|---|---|---|---|---|\n";
    for (const auto& c : d.causes)
      for (const auto& f : c.findings)
        for (std::size_t k = 0; k < f.params.size(); ++k) {
          s << "| " << f.cause << " | " << f.channel << " | " << f.params[k].first << " | " << r3(f.params[k].second)
            << " | ";
          for (const auto& iv : f.interval)
            if (iv.first == f.params[k].first) s << "[" << r3(iv.second.first) << ", " << r3(iv.second.second) << "]";
          s << " |\n";
        }
    if (d.best >= 0) {
      const auto& b = d.causes[static_cast<std::size_t>(d.best)];
      s << "\n**Cause: " << b.cause << "** (" << b.extension << "). Held-out horizontal error "
        << r3(b.error_before_m) << " -> " << r3(b.error_after_m) << " m, mean NEES " << r3(b.anees_before) << " -> "
        << r3(b.anees_after) << ", p = " << formatReadable(b.p_value, 2)
        << ". The extension: model_extended.yaml and filter_extended.yaml.\n";
    } else if (d.causes.front().significant && !d.causes.front().given.empty()) {
      const auto& b = d.causes.front();
      s << "\n**Undecided between " << b.cause << " and " << b.given << "**: " << b.cause
        << " has the larger held-out gain, but nothing beyond " << b.given << "'s extension (gain "
        << r3(b.gain_given) << ", p = " << formatReadable(b.p_given, 2)
        << "): the held-out outages do not tell the two apart. No extension is proposed; a run with other "
           "motion (turns, speed changes, longer outages) may separate them.\n";
    } else {
      s << "\nNo cause has a significant held-out gain: no extension is proposed.\n";
    }
  }
  if (!d.notices.empty()) {
    s << "\n## Notices\n\n";
    for (const auto& n : d.notices) s << "- " << n << "\n";
  }
  return s.str();
}

std::string runDiagnosisSummary(const RunDiagnosis& d) {
  std::ostringstream s;
  s << "run diagnosis of " << d.rawlog << " with " << d.model_source << ": " << d.verdict << " (" << d.tests
    << " tests, family-wise false-alarm rate " << formatNumber(d.alpha) << ")\n";
  if (d.verdict == "undetermined")
    for (const auto& r : d.reasons) s << "  " << r << "\n";
  for (const auto& c : d.comparisons)
    s << "  " << formatNumber(c.duration_s) << " s " << c.quantity << ": measured/predicted RMS " << r3(c.ratio) << " ["
      << r3(c.ratio_lo) << ", " << r3(c.ratio_hi) << "]" << (c.rejects ? " rejects" : "") << "\n";
  for (const auto& dd : d.durations)
    s << "  " << formatNumber(dd.duration_s) << " s mean NEES " << r3(dd.anees) << " band [" << r3(dd.anees_lo) << ", "
      << r3(dd.anees_hi) << "]" << (dd.anees_rejects ? " outside" : "") << "\n";
  for (const auto& c : d.causes)
    s << "  cause " << c.cause << ": held-out gain " << r3(c.gain) << ", p = " << formatReadable(c.p_value, 2)
      << (c.significant ? " significant" : "")
      << (c.given.empty() ? std::string()
                          : "; on top of " + c.given + ": gain " + r3(c.gain_given) + ", p = " +
                                formatReadable(c.p_given, 2) + (c.adds ? ", named" : ", not named"))
      << "\n";
  s << "  " << formatFixed(d.wall_s, 1) << " s\n";
  return s.str();
}

std::size_t writeRunDiagnosisOutputs(const RunDiagnosis& d, const std::string& input_json, OutputSet& out) {
  out.writeText("run_diagnosis.json", runDiagnosisJson(d, input_json));
  out.writeText("report.md", runDiagnosisMarkdown(d));
  writeTiming(out, {{"wall_s", d.wall_s}});  // wall clock kept apart
  if (d.best >= 0) {
    const auto& b = d.causes[static_cast<std::size_t>(d.best)];
    out.writeText("model_extended.yaml",
                  stochastic::toYaml(b.model_after, "extended by navimpact diagnose --run (" + b.cause + ") from " +
                                                        d.rawlog + ", seed " + std::to_string(d.seed)));
    std::ostringstream f;
    f << "# Filter of the extension found by navimpact diagnose --run (" << b.cause << ") on " << d.rawlog << ".\n"
      << "# Use with navimpact replay --config THIS (keys as in the replay configuration).\n"
      << "model: model_extended.yaml\n";
    if (b.gnss_sigma_h_m || b.gnss_sigma_v_m) {
      f << "noise:\n";
      if (b.gnss_sigma_h_m) f << "  sigma_pos_h_m: " << formatExact(*b.gnss_sigma_h_m) << "\n";
      if (b.gnss_sigma_v_m) f << "  sigma_pos_v_m: " << formatExact(*b.gnss_sigma_v_m) << "\n";
    }
    if (b.extra_states) {
      const filter::ExtraStates& x = *b.extra_states;
      auto v3 = [](const Eigen::Vector3d& v) {
        return "[" + formatExact(v(0)) + ", " + formatExact(v(1)) + ", " + formatExact(v(2)) + "]";
      };
      f << "filter:\n  extra_states:\n";
      if (x.gyro_scale_sigma > 0 || x.acc_scale_sigma > 0) {
        f << "    scale_factor:\n";
        if (x.gyro_scale_sigma > 0)
          f << "      gyro_sigma: " << formatExact(x.gyro_scale_sigma) << "\n      gyro: " << v3(x.gyro_scale0) << "\n";
        if (x.acc_scale_sigma > 0)
          f << "      acc_sigma: " << formatExact(x.acc_scale_sigma) << "\n      acc: " << v3(x.acc_scale0) << "\n";
      }
      if (x.gyro_misalignment_sigma_rad > 0 || x.acc_misalignment_sigma_rad > 0) {
        f << "    misalignment:\n";
        if (x.gyro_misalignment_sigma_rad > 0)
          f << "      gyro_sigma_rad: " << formatExact(x.gyro_misalignment_sigma_rad)
            << "\n      gyro_rad: " << v3(x.gyro_misalignment0_rad) << "\n";
        if (x.acc_misalignment_sigma_rad > 0)
          f << "      acc_sigma_rad: " << formatExact(x.acc_misalignment_sigma_rad)
            << "\n      acc_rad: " << v3(x.acc_misalignment0_rad) << "\n";
      }
      if (x.lever_arm_sigma_m > 0)
        f << "    lever_arm:\n      sigma_m: " << formatExact(x.lever_arm_sigma_m)
          << "\n      error_m: " << v3(x.lever_arm_error0_m) << "\n";
      if (x.time_offset_sigma_s > 0)
        f << "    time_offset:\n      sigma_s: " << formatExact(x.time_offset_sigma_s)
          << "\n      offset_s: " << formatExact(x.time_offset0_s) << "\n";
    }
    out.writeText("filter_extended.yaml", f.str());
  }
  // One panel per (quantity, duration): x = measured outage index, the simulated
  // 5-95 % band and median across, the measured end errors as points.
  std::vector<std::string> qs;
  for (const auto& c : d.comparisons)
    if (std::find(qs.begin(), qs.end(), c.quantity) == qs.end()) qs.push_back(c.quantity);
  const std::size_t D = d.durations.size();
  plot::Figure fig;
  fig.rows = static_cast<int>(qs.size());
  fig.cols = static_cast<int>(D);
  fig.width = std::max(700, 420 * fig.cols);
  fig.height = std::max(500, 330 * fig.rows);
  fig.title = "Outage-end error: simulation (" + std::to_string(d.realisations) + " realisations) vs measured";
  for (const auto& q : qs)
    for (const auto& dd : d.durations) {
      plot::Axes ax;
      const analysis::QuantityComparison* c = nullptr;
      for (const auto& x : d.comparisons)
        if (x.quantity == q && x.duration_s == dd.duration_s) c = &x;
      ax.title = formatNumber(dd.duration_s) + " s, " + q;
      ax.xlabel = "outage";
      ax.ylabel = c ? "error [" + c->unit + "]" : "";
      if (c) {
        const double n = static_cast<double>(c->measured.size());
        plot::Band b{"simulated 5-95 %", {0.5, n + 0.5}, {c->predicted_p05, c->predicted_p05},
                     {c->predicted_p95, c->predicted_p95}, plot::palette(0), 0.25};
        ax.bands.push_back(b);
        ax.hlines.push_back({"simulated median", c->predicted_p50, plot::palette(0), plot::LineStyle::Dashed});
        plot::Series m{"measured", {}, {}, plot::palette(1), plot::LineStyle::None, plot::Marker::FilledCircle, 2.0};
        for (std::size_t k = 0; k < c->measured.size(); ++k) {
          m.x.push_back(double(k + 1));
          m.y.push_back(c->measured[k]);
        }
        ax.series.push_back(m);
        ax.xlim = std::make_pair(0.5, n + 0.5);
        double top = c->predicted_p95;
        for (double v : c->measured) top = std::max(top, v);
        ax.ylim = std::make_pair(0.0, top > 0 ? 1.1 * top : 1.0);
      }
      fig.axes.push_back(ax);
    }
  if (!fig.axes.empty()) {
    plot::savePng(fig, out.stage("predicted_vs_measured.png").string());
    return 1;
  }
  return 0;
}

}  // namespace navimpact::report
