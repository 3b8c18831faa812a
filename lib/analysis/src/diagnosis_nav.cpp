// Navigation gain of navimpact diagnose: measured static errors as the truth
// along a trajectory (Khaghani et al. 2019), the filter run with the user's
// model and with the extension over the same realisations (paired), through
// analysis::runNav. Built from the same library pieces as the study
// (emulation::perfectImu / staticImuErrors / simulateGnss / simulateBaro).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include <boost/math/distributions/binomial.hpp>
#include <boost/math/distributions/students_t.hpp>

#include "navimpact/analysis/diagnosis.hpp"
#include "navimpact/filter/model_entry.hpp"
#include "navimpact/analysis/run_plan.hpp"
#include "navimpact/analysis/study.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/parallel.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/filter/error_model.hpp"
#include "navimpact/filter/state_layout.hpp"
#include "navimpact/stochastic/simulate.hpp"

namespace navimpact::analysis {

struct NavGainPlan {
  NavGainOptions opt;
  RunPlan run;
  std::size_t samples = 0;             ///< recording samples
};

std::shared_ptr<const NavGainPlan> prepareNavGain(const NavGainOptions& opt, double rate,
                                                  std::size_t samples) {
  if (opt.runs < 2 || opt.runs > limits::kMaxMonteCarloRuns)
    throw Error("navigation gain: --nav-runs must be in [2, " + std::to_string(limits::kMaxMonteCarloRuns) + "], got " +
                std::to_string(opt.runs));
  if (opt.outages.empty()) throw Error("navigation gain: give at least one --outage START:DURATION");
  if (!(rate > 0)) throw Error("navigation gain: recording rate must be > 0");
  auto plan = std::make_shared<NavGainPlan>();
  plan->opt = opt;
  plan->samples = samples;
  RunPlanOptions ro;
  ro.trajectory = opt.trajectory;
  ro.smoothing = opt.smoothing;
  ro.imu_rate_hz = rate;
  ro.outages = opt.outages;
  ro.outage_name = "--outage";
  ro.record_rate_hz = opt.record_rate_hz;
  ro.outage_record_rate_hz = opt.outage_record_rate_hz;
  ro.gnss = opt.gnss;
  ro.baro = opt.baro;
  ro.baro_in_outage = opt.baro_in_outage;
  ro.ekf.propagate_every =
      opt.propagate_every > 0 ? opt.propagate_every : std::max(1, static_cast<int>(std::lround(rate / 20.0)));
  ro.initial_sigma = opt.initial_sigma;
  plan->run = planRuns(ro);
  {
    // Work and result memory, estimated before the runs (README "Ranges and budgets"):
    // per run its emulation and two filters; per run and model 3 numbers per
    // recorded epoch and 4 per outage.
    const double steps = double(opt.runs) * double(plan->run.samples()) * 3.0;
    const double bytes = double(opt.runs) * 2.0 *
                         (3.0 * double(plan->run.truth.t.size()) + 4.0 * double(plan->run.nav.outages.size())) * 8.0;
    const std::string place = "navigation gain: --nav-runs " + std::to_string(opt.runs);
    limits::checkBudget({{place, "the runs", steps, limits::kDefaultFilterStepBudget, "IMU steps",
                          "runs x " + std::to_string(plan->run.samples()) + " samples x 3: emulation and two filters",
                          "lower --nav-runs"},
                         {place, "the runs' results", bytes / 1e6, limits::kDefaultMemoryBudgetBytes / 1e6, "MB", "",
                          "lower --nav-runs"}},
                        opt.allow_large);
  }
  if (plan->run.samples() > samples)
    throw Error("static recording too short for the navigation gain: " + formatNumber(samples / rate, 6) +
                " s available, " + formatNumber(plan->run.duration_s(), 6) + " s needed for the trajectory " +
                opt.trajectory.file);
  return plan;
}

namespace {

struct RunOut {
  // per model (0 before, 1 after): per outage h, v, drift, nees; per epoch h, v, sigma_h
  std::array<std::vector<double>, 2> h, v, drift, nees;
  std::array<std::vector<double>, 2> eh, ev, sh;
};

double exactSignP(int wins, int n) {
  if (n <= 0) return 1.0;
  boost::math::binomial bin(n, 0.5);
  const int k = std::min(wins, n - wins);
  return std::min(1.0, 2.0 * boost::math::cdf(bin, static_cast<double>(k)));
}

double pairedTP(const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t n = a.size();
  if (n < 2) return 1.0;
  double m = 0;
  for (std::size_t i = 0; i < n; ++i) m += a[i] - b[i];
  m /= double(n);
  double v = 0;
  for (std::size_t i = 0; i < n; ++i) v += (a[i] - b[i] - m) * (a[i] - b[i] - m);
  v /= double(n - 1);
  if (!(v > 0)) return m == 0 ? 1.0 : 0.0;
  const double t = m / std::sqrt(v / double(n));
  boost::math::students_t st(static_cast<double>(n - 1));
  return std::min(1.0, 2.0 * boost::math::cdf(boost::math::complement(st, std::abs(t))));
}

double mean(const std::vector<double>& x) {
  double s = 0;
  for (double v : x) s += v;
  return x.empty() ? 0.0 : s / double(x.size());
}

}  // namespace

void addNavigationGain(Diagnosis& d, const ImuSeries& data, const NavGainPlan& p,
                       const std::function<void(double)>& progress) {
  const auto wall0 = std::chrono::steady_clock::now();
  const NavGainOptions& opt = p.opt;
  const RunPlan& run = p.run;
  if (std::abs(data.rate_hz - run.rate_hz) > 1e-9 * run.rate_hz || data.size() != p.samples)
    throw Error("navigation gain: the plan was prepared for another recording");
  const std::size_t n = run.samples();
  NavGain g;
  g.imu_rate_hz = run.rate_hz;
  g.duration_s = run.duration_s();
  g.runs = opt.runs;
  g.seed = opt.seed;
  g.trajectory = opt.trajectory.file + " (" + formatNumber(g.duration_s, 6) + " s used)";

  // Held-out windows: the second half of the recording, which the extension
  // (first-half fit) has not seen, when it holds the emulation.
  const std::size_t N = data.size(), nh = N / 2;
  const bool held_out = (N - nh) >= n;
  ImuSeries rec;
  rec.source = data.source;
  rec.rate_hz = data.rate_hz;
  rec.channels = data.channels;
  std::size_t first = 0;
  if (held_out) {
    first = nh;
    for (auto& c : rec.channels) c.x.erase(c.x.begin(), c.x.begin() + static_cast<std::ptrdiff_t>(nh));
  }
  stochastic::ImuModel after = d.model_after;
  stochastic::ImuModel before = d.model_before;
  for (const auto& c : d.channels) {
    before.forChannel(c.name) = c.model_before;
    after.forChannel(c.name) = held_out ? c.model_after_half : c.model_after;
  }
  {
    // GMs with T at most the covariance propagation interval enter the filter
    // as white noise (filter::ImuErrorOptions::white_gm_below_s); say so.
    std::size_t replaced = 0;
    for (const auto* m : {&before, &after})
      replaced += filter::layoutFor(*m, run.nav.ekf).layout.notes().size();
    const double t_min = run.nav.ekf.propagate_every / run.rate_hz;
    if (replaced > 0)
      g.filter_note = std::to_string(replaced) +
                      " Gauss-Markov term(s) with T at most the covariance propagation interval (" +
                      formatNumber(t_min, 3) + " s) entered the filter as white noise of the same long-run variance sigma^2 (1 + phi) / (1 - phi), "
                      "phi = exp(-dt/T) (the EKF cannot carry them), alike before and after";
  }
  g.filter_after = held_out
                       ? "the extension fitted on the first half of the record (model_after_first_half); "
                         "the truth windows come from the second half, which that fit has not seen"
                       : "the whole-record extension (model_after): the second half of the record is "
                         "shorter than the emulation, so truth windows and fit share data (in-sample)";
  if (!held_out)
    d.notices.push_back("navigation gain is in-sample: the held-out half (" + formatNumber((N - nh) / run.rate_hz, 6) +
                        " s) is shorter than the trajectory (" + formatNumber(g.duration_s, 6) + " s)");
  // Evenly spaced window offsets over the available span.
  const std::size_t avail = rec.size() - n;
  std::vector<std::size_t> offs;
  for (int r = 0; r < opt.runs; ++r) {
    const double frac = opt.runs > 1 ? double(r) / double(opt.runs - 1) : 0.0;
    const std::size_t off = static_cast<std::size_t>(std::floor(frac * double(avail)));
    offs.push_back(off);
    g.window_offsets_s.push_back(double(first + off) / run.rate_hz);
  }
  g.truth = "measured static recording " + data.source + ": run r takes the " + formatNumber(g.duration_s, 6) +
            " s window starting at offset r/(R-1) of the " + (held_out ? "second half" : "whole record") +
            " (R = " + std::to_string(opt.runs) + "), window mean removed per axis";
  {
    std::ostringstream st;
    st << "IMU " << formatNumber(run.rate_hz, 6) << " Hz; GNSS " << formatNumber(opt.gnss.rate_hz, 4)
       << " Hz, position sigma " << formatNumber(opt.gnss.sigma_pos_h_m, 4) << " m horizontal / "
       << formatNumber(opt.gnss.sigma_pos_v_m, 4) << " m vertical, velocity sigma "
       << formatNumber(opt.gnss.sigma_vel_h_mps, 4) << " / " << formatNumber(opt.gnss.sigma_vel_v_mps, 4)
       << " m/s; barometer " << formatNumber(opt.baro.rate_hz, 4) << " Hz, sigma " << formatNumber(opt.baro.sigma_m, 4)
       << " m, " << (opt.baro_in_outage ? "kept" : "off") << " during outages; EKF covariance every "
       << run.nav.ekf.propagate_every << " IMU samples; initial error sigmas " << formatNumber(opt.initial_sigma(0), 3)
       << " m, " << formatNumber(opt.initial_sigma(3), 3) << " m/s, roll/pitch "
       << formatNumber(opt.initial_sigma(6) / units::kDeg, 3) << " deg, yaw "
       << formatNumber(opt.initial_sigma(8) / units::kDeg, 3) << " deg (drawn per run, same for both models)";
    g.settings = st.str();
  }

  const std::size_t O = run.nav.outages.size(), E = run.truth.t.size();
  std::vector<RunOut> outs(opt.runs);
  TaskProgress each;
  if (progress) each = [&](std::size_t done, std::size_t count) { progress(double(done) / double(count)); };
  parallelFor(static_cast<std::size_t>(opt.runs), static_cast<unsigned>(std::max(opt.threads, 0)), [&](std::size_t r) {
    const std::uint64_t seed = stochastic::deriveSeed(opt.seed, static_cast<std::uint64_t>(r));
    emulation::StaticRecordingSpec spec;
    spec.file = data.source;
    spec.offset_s = double(offs[r]) / run.rate_hz;
    const auto err = emulation::staticImuErrors(rec, spec, run.rate_hz, n).axis;
    const EmulatedRun emulated = run.emulate(err, seed);
    const NavRunInput in = run.input(emulated);
    RunOut& o = outs[r];
    for (int m = 0; m < 2; ++m) {
      const NavRunResult res = runNav(in, m == 0 ? before : after, run.nav);
      if (res.epochs.size() != E)
        throw Error("navigation gain: run " + std::to_string(r) + " recorded " +
                    std::to_string(res.epochs.size()) + " epochs, expected " + std::to_string(E));
      for (std::size_t e = 0; e < E; ++e) {
        const auto& ep = res.epochs[e];
        o.eh[m].push_back(std::hypot(ep.err(0), ep.err(1)));
        o.ev[m].push_back(std::abs(ep.err(2)));
        o.sh[m].push_back(std::hypot(ep.sigma(0), ep.sigma(1)));
      }
      for (std::size_t q = 0; q < O; ++q) {
        const auto& ep = res.epochs[run.outage_end_epoch[q]];
        o.h[m].push_back(std::hypot(ep.err(0), ep.err(1)));
        o.v[m].push_back(std::abs(ep.err(2)));
        o.nees[m].push_back(ep.nees[0]);
        o.drift[m].push_back(res.outages[q].max_drift_h);
      }
    }
  }, each);

  // Per outage, paired over runs.
  for (std::size_t q = 0; q < O; ++q) {
    NavOutageGain og;
    og.start_s = run.nav.outages[q].start_s - run.t0;
    og.duration_s = run.nav.outages[q].end_s - run.nav.outages[q].start_s;
    for (const auto& o : outs) {
      og.h_before.push_back(o.h[0][q]);
      og.h_after.push_back(o.h[1][q]);
      og.v_before.push_back(o.v[0][q]);
      og.v_after.push_back(o.v[1][q]);
      og.drift_before.push_back(o.drift[0][q]);
      og.drift_after.push_back(o.drift[1][q]);
      og.nees_before.push_back(o.nees[0][q]);
      og.nees_after.push_back(o.nees[1][q]);
    }
    og.mean_h_before = mean(og.h_before);
    og.mean_h_after = mean(og.h_after);
    og.mean_v_before = mean(og.v_before);
    og.mean_v_after = mean(og.v_after);
    og.mean_drift_before = mean(og.drift_before);
    og.mean_drift_after = mean(og.drift_after);
    og.anees_before = mean(og.nees_before);
    og.anees_after = mean(og.nees_after);
    og.nees_band = aneesBand(static_cast<std::size_t>(opt.runs), 3, 0.95);
    int ties = 0;
    for (int r = 0; r < opt.runs; ++r) {
      if (og.h_after[r] < og.h_before[r]) ++og.wins;
      else if (og.h_after[r] == og.h_before[r]) ++ties;
    }
    og.sign_p = exactSignP(og.wins, opt.runs - ties);
    og.t_p = pairedTP(og.h_before, og.h_after);
    og.significant = og.sign_p < 0.05;
    g.outages.push_back(og);
  }
  // RMS time series for the figure.
  g.t_s.resize(E);
  for (std::size_t e = 0; e < E; ++e) {
    g.t_s[e] = run.truth.t[e] - run.t0;
    double hb = 0, ha = 0, vb = 0, va = 0, sb = 0, sa = 0;
    for (const auto& o : outs) {
      hb += o.eh[0][e] * o.eh[0][e];
      ha += o.eh[1][e] * o.eh[1][e];
      vb += o.ev[0][e] * o.ev[0][e];
      va += o.ev[1][e] * o.ev[1][e];
      sb += o.sh[0][e] * o.sh[0][e];
      sa += o.sh[1][e] * o.sh[1][e];
    }
    const double R = opt.runs;
    g.rms_h_before.push_back(std::sqrt(hb / R));
    g.rms_h_after.push_back(std::sqrt(ha / R));
    g.rms_v_before.push_back(std::sqrt(vb / R));
    g.rms_v_after.push_back(std::sqrt(va / R));
    g.sig_h_before.push_back(std::sqrt(sb / R));
    g.sig_h_after.push_back(std::sqrt(sa / R));
  }
  g.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  d.navigation = std::move(g);
}

}  // namespace navimpact::analysis
