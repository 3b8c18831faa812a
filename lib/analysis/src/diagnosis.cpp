// navimpact diagnose: what a simulation with the user's model gets wrong, why,
// and what an extended model gains (see diagnosis.hpp for the method). Every
// channel goes through the pipeline in diagnoseChannel(), one function per
// step: 1-3 in diagnosis_detect.cpp, the cause search of step 4 in
// diagnosis_search.cpp, the WV test of step 4, the extension (5) and the
// held-out gain (6) here; the channels run in parallel in diagnose().
#include "navimpact/analysis/diagnosis.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>
#include <vector>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>

#include "diagnosis_internal.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/core/parallel.hpp"
#include "navimpact/gmwm/estimator.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"
#include "navimpact/stochastic/simulate.hpp"

namespace navimpact::analysis {

const char* causeName(Cause c) {
  switch (c) {
    case Cause::WhiteNoise: return "white_noise";
    case Cause::QuantizationNoise: return "quantization_noise";
    case Cause::RandomWalk: return "random_walk";
    case Cause::Drift: return "drift";
    case Cause::GaussMarkov: return "gauss_markov";
    case Cause::Sinusoid: return "sinusoid";
    case Cause::LevelShift: return "level_shift";
    case Cause::Outliers: return "outliers";
  }
  return "?";
}

double Finding::get(const std::string& key) const {
  for (const auto& kv : params)
    if (kv.first == key) return kv.second;
  return std::numeric_limits<double>::quiet_NaN();
}

std::string channelUnit(const std::string& channel) {
  return channel.rfind("gyro", 0) == 0 ? "rad/s" : "m/s^2";
}

namespace detail {

namespace {
// Wilson-Hilferty: (X/nu)^(1/3) is close to normal with mean 1 - v and
// variance v = 2/(9 nu) (Johnson, Kotz & Balakrishnan 1994, eq. 18.24).
double whVar(double nu) { return 2.0 / (9.0 * nu); }
double whZ(double nu, double x) { return (std::cbrt(x / nu) - (1.0 - whVar(nu))) / std::sqrt(whVar(nu)); }
double whX(double nu, double z) {
  return nu * std::pow(std::max(0.0, 1.0 - whVar(nu) + z * std::sqrt(whVar(nu))), 3);
}
}  // namespace

double chiQuantile(double nu, double p) {
  try {
    return boost::math::quantile(boost::math::chi_squared(nu), p);
  } catch (const std::exception&) {
    return whX(nu, boost::math::quantile(boost::math::normal(), p));
  }
}
double chiUpperQuantile(double nu, double q) {
  try {
    return boost::math::quantile(boost::math::complement(boost::math::chi_squared(nu), q));
  } catch (const std::exception&) {
    return whX(nu, boost::math::quantile(boost::math::complement(boost::math::normal(), q)));
  }
}
std::pair<double, double> chiTails(double nu, double x) {
  try {
    const boost::math::chi_squared chi(nu);
    return {boost::math::cdf(chi, x), boost::math::cdf(boost::math::complement(chi, x))};
  } catch (const std::exception&) {
    const boost::math::normal n;
    const double z = whZ(nu, x);
    return {boost::math::cdf(n, z), boost::math::cdf(boost::math::complement(n, z))};
  }
}

std::vector<ScaleCheck> checkScales(const gmwm::WaveletVariance& wv, const std::vector<double>& nu_m,
                                    const std::vector<double>& dof, double p_thr,
                                    const std::vector<double>& env_lo,
                                    const std::vector<double>& env_hi) {
  std::vector<ScaleCheck> out(wv.scales());
  for (int j = 0; j < wv.scales(); ++j) {
    ScaleCheck& s = out[j];
    s.tau_s = wv.tau(j) / wv.rate_hz;
    s.measured = wv.wv(j);
    s.model = nu_m[j];
    s.dof = dof[j];
    s.env_low = env_lo.empty() ? kNaN : env_lo[j];
    s.env_high = env_hi.empty() ? kNaN : env_hi[j];
    if (!(nu_m[j] > 0)) {
      s.ratio = std::numeric_limits<double>::infinity();
      s.p_value = 0;
      s.outside95 = s.significant = true;
      s.ci_low = s.ci_high = 0;
      s.ci_widths = std::numeric_limits<double>::infinity();
      continue;
    }
    s.ci_low = nu_m[j] * chiQuantile(dof[j], 0.025) / dof[j];
    s.ci_high = nu_m[j] * chiQuantile(dof[j], 0.975) / dof[j];
    s.ratio = s.measured / s.model;
    const double stat = dof[j] * s.ratio;
    const auto [lo, hi] = chiTails(dof[j], stat);
    s.p_value = std::min(1.0, 2.0 * std::min(lo, hi));
    const double width = s.ci_high - s.ci_low;
    if (s.measured > s.ci_high) s.ci_widths = (s.measured - s.ci_high) / width;
    else if (s.measured < s.ci_low) s.ci_widths = -(s.ci_low - s.measured) / width;
    else s.ci_widths = 0;
    s.outside95 = s.ci_widths != 0;
    s.significant = s.p_value < p_thr;
  }
  return out;
}

}  // namespace detail

namespace {

using namespace detail;

/// What the channels share: the record, the model at its rate, the options,
/// the alpha budget per channel and the progress reported so far.
struct Shared {
  const ImuSeries* data;
  const stochastic::ImuModel* model;
  const DiagnoseOptions* opt;
  Budget per_channel;
  double channels = 1;
  std::atomic<int> done_units{0};
  int total_units = 1;
  std::mutex mu;
  void tick(const std::string& stage, int units = 1) {
    const int d = done_units += units;
    if (opt->progress) {
      std::lock_guard<std::mutex> lk(mu);
      opt->progress(std::min(1.0, static_cast<double>(d) / total_units), stage);
    }
  }
};

/// The context of channel @p ci: its record's rate, length and start, the
/// user's model for it, its share of alpha, the options the steps read.
ChannelContext channelContext(const Shared& sh, int ci) {
  const ImuChannel& chan = sh.data->channels[ci];
  const DiagnoseOptions& opt = *sh.opt;
  ChannelContext ctx;
  ctx.name = chan.name;
  ctx.unit = channelUnit(chan.name);
  ctx.index = ci;
  ctx.rate = sh.data->rate_hz;
  ctx.n = chan.x.size();
  ctx.record = static_cast<double>(ctx.n) / ctx.rate;
  ctx.t0 = sh.data->t0_s;
  ctx.m0 = sh.model->forChannel(chan.name);
  ctx.m0n = withoutSin(ctx.m0);
  ctx.B = sh.per_channel;
  ctx.channels = sh.channels;
  ctx.max_terms = opt.max_terms;
  ctx.simulations = opt.simulations;
  ctx.seed = opt.seed;
  return ctx;
}

/// @p x with its mean removed.
std::vector<double> withoutMean(std::vector<double> x) {
  double mean = 0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  for (double& v : x) v -= mean;
  return x;
}

/// 4, first part. The WV of the raw and of the cleaned record against the
/// user's model, with the model's simulations: their envelope, the dof of
/// each scale lowered to what they show, the per-scale threshold (Bonferroni
/// over scales) and cd.scales (the raw record against the model). A WV is
/// recomputed only where the record changed since @p wv_pre (@p raw_differs:
/// steps 1-2 took something out; @p cleaned_differs: step 3 did).
WvCheck checkWv(Shared& sh, const ChannelContext& ctx, const std::vector<double>& raw, const std::vector<double>& x,
                const gmwm::WaveletVariance& wv_pre, bool raw_differs, bool cleaned_differs, ChannelDiagnosis& cd) {
  const double rate = ctx.rate;
  const std::size_t n = ctx.n;
  const Model& m0 = ctx.m0;
  WvCheck w;
  w.raw = raw_differs ? gmwm::waveletVariance(raw.data(), n, rate) : wv_pre;
  w.cleaned = cleaned_differs ? gmwm::waveletVariance(x.data(), n, rate) : wv_pre;
  w.tau = toStd(wv_pre.tau);
  const int J = w.raw.scales();
  const auto nu0 = wvOf(m0, w.tau);
  std::vector<double> env_lo(J, std::numeric_limits<double>::infinity()), env_hi(J, 0.0);
  std::vector<double>& dof = w.dof;
  dof = toStd(w.raw.eta);
  if (!m0.empty() && ctx.simulations >= 2) {
    std::vector<double> s1(J, 0.0), s2(J, 0.0);
    for (int s = 0; s < ctx.simulations; ++s) {
      const auto sim = stochastic::simulate(
          m0, n, stochastic::deriveSeed(ctx.seed, 1000u * static_cast<unsigned>(ctx.index) + s));
      // a simulation of the model, not the record: its errors name the model
      // (a GM with T = 1e300 s simulates as a constant, which was blamed on the CSV)
      const auto ws = [&] {
        try {
          return gmwm::waveletVariance(sim.data(), n, rate);
        } catch (const Error& e) {
          throw Error("the model's simulation of channel " + cd.name + " (" + stochastic::formatTerms(m0.terms) +
                      "): " + e.what());
        }
      }();
      for (int j = 0; j < J && j < ws.scales(); ++j) {
        env_lo[j] = std::min(env_lo[j], ws.wv(j));
        env_hi[j] = std::max(env_hi[j], ws.wv(j));
        const double r = nu0[j] > 0 ? ws.wv(j) / nu0[j] : 0;
        s1[j] += r;
        s2[j] += r * r;
      }
      sh.tick(cd.name + ": simulations");
    }
    // Moment-matched dof of the simulated ratios (var of chi2_eta / eta = 2 / eta),
    // used where fewer than eta (the theory would be over-confident there).
    const double S = ctx.simulations;
    for (int j = 0; j < J; ++j) {
      const double m = s1[j] / S, v = (s2[j] - S * m * m) / (S - 1);
      if (v > 0 && m > 0) dof[j] = std::max(1.0, std::min(dof[j], 2.0 * m * m / v));
    }
  } else {
    env_lo.clear();
    env_hi.clear();
    sh.tick(cd.name + ": simulations", ctx.simulations);
  }
  w.p_thr = ctx.B.wv / J;  // two-sided p-value vs alpha / J (Bonferroni over scales)
  cd.wv_threshold_p = w.p_thr;
  cd.scales = checkScales(w.raw, nu0, dof, w.p_thr, env_lo, env_hi);
  w.full = WvData{w.tau, toStd(w.cleaned.wv), dof, static_cast<double>(n)};
  // The WV test on the cleaned record against the model without its SIN
  // terms (the lines are subtracted from the record).
  w.cleaned_vs_model = checkScales(w.cleaned, wvOf(ctx.m0n, w.tau), dof, w.p_thr, env_lo, env_hi);
  return w;
}

/// The dof of the WV of one half of the record: its own, lowered in the
/// proportion the simulations lowered the whole record's (WvCheck::dof).
std::vector<double> halfDof(const gmwm::WaveletVariance& half, const WvCheck& w) {
  std::vector<double> d(half.scales());
  for (int j = 0; j < half.scales(); ++j) {
    const double ratio = w.raw.eta(j) > 0 ? w.dof[j] / w.raw.eta(j) : 1.0;
    d[j] = std::max(1.0, half.eta(j) * std::min(1.0, ratio));
  }
  return d;
}

/// 5. The extension: the terms found @p S added to the user's model, on the
/// whole cleaned record and, backfitted again, on the first half of @p x
/// (for the held-out gain), each refitted by GMWM when a broadband term was
/// found; the user's SIN terms and the lines found join as SIN terms. Fills
/// the models after, their refits, scales_after and wv_cleaned of @p cd.
/// Returns the parameters the broadband terms add.
int extendModel(const ChannelContext& ctx, const std::vector<double>& x, const WvCheck& w,
                const std::vector<Candidate>& S, const std::vector<detect::SpectralLine>& lines,
                ChannelDiagnosis& cd) {
  const Model& m0n = ctx.m0n;
  const std::size_t nh = ctx.n / 2;
  const auto wv_h1 = gmwm::waveletVariance(x.data(), nh, ctx.rate);
  const WvData h1{toStd(wv_h1.tau), toStd(wv_h1.wv), halfDof(wv_h1, w), static_cast<double>(nh)};
  int added_params = 0;
  for (const auto& c : S) added_params += c.params;
  Model m_full = merged(m0n, S);
  std::vector<Candidate> Sh = S;  // the same terms on the first half
  if (!Sh.empty()) backfit(m0n, Sh, h1);
  Model m_half = merged(m0n, Sh);
  if (added_params > 0) {
    m_half = gmwmRefit(m_half, wv_h1, h1, &cd.refit_half);
    m_full = gmwmRefit(m_full, w.cleaned, w.full, &cd.refit_full);
  }
  cd.scales_after = checkScales(w.cleaned, wvOf(m_full, w.tau), w.dof, w.p_thr, {}, {});
  // The user's SIN terms and the lines found become SIN terms of the extension.
  for (const auto& p : ctx.m0.terms)
    if (p.kind == ProcessKind::SIN) {
      m_full.terms.push_back(p);
      m_half.terms.push_back(p);
    }
  for (const auto& L : lines) {
    m_full.terms.push_back(Process::sin(L.amplitude, L.freq_hz));
    m_half.terms.push_back(Process::sin(L.amplitude, L.freq_hz));
  }
  cd.model_after = m_full;
  cd.model_after_half = m_half;
  cd.wv_cleaned = toStd(w.cleaned.wv);
  return added_params;
}

int countOutside(const std::vector<ScaleCheck>& s) {
  int c = 0;
  for (const auto& x : s) c += x.outside95 ? 1 : 0;
  return c;
}

/// Paired one-sided test over scales of the per-scale deviances (Vuong 1989
/// style): z = mean(d_b - d_a) / (sd / sqrt(J)), H1: the extension fits better.
void pairedScaleTest(const std::vector<double>& nu_b_hat, const std::vector<double>& nu_b,
                     const std::vector<double>& eta_b, const std::vector<double>& nu_a_hat,
                     const std::vector<double>& nu_a, const std::vector<double>& eta_a,
                     double* z, double* p) {
  const std::size_t J = std::min(nu_b_hat.size(), nu_a_hat.size());
  std::vector<double> d(J);
  double m = 0;
  for (std::size_t j = 0; j < J; ++j) {
    d[j] = wvDeviance({nu_b_hat[j]}, {nu_b[j]}, {eta_b[j]}) - wvDeviance({nu_a_hat[j]}, {nu_a[j]}, {eta_a[j]});
    m += d[j];
  }
  m /= static_cast<double>(std::max<std::size_t>(1, J));
  double v = 0;
  for (double x : d) v += (x - m) * (x - m);
  v /= static_cast<double>(std::max<std::size_t>(2, J) - 1);
  if (!(v > 0)) {
    *z = m > 0 ? std::numeric_limits<double>::infinity() : 0.0;
    *p = m > 0 ? 0.0 : 1.0;
    return;
  }
  *z = m / std::sqrt(v / static_cast<double>(J));
  *p = boost::math::cdf(boost::math::complement(boost::math::normal(), *z));
}

/// 6. Gain, held out: the user's model on the raw second half against the
/// first-half extension @p after_half (its lines, outliers and steps removed
/// with the detectors' whole-record estimates) on the cleaned second half.
/// Without a fitted broadband term (@p added_params 0: cleaning or lines
/// only) nothing was fitted to the WV and the whole record is used, with the
/// whole-record extension @p after_full. @p lines: the lines found.
GainCheck heldOutGain(const ChannelContext& ctx, const std::vector<double>& raw, const std::vector<double>& x,
                      const WvCheck& w, const Model& after_full, const Model& after_half, int added_params,
                      std::size_t lines) {
  const Model& m0 = ctx.m0;
  const std::size_t n = ctx.n, nh = n / 2;
  GainCheck g;
  const bool held_out = added_params > 0;
  g.basis = held_out ? "second_half" : "full_record";
  const gmwm::WaveletVariance wb = held_out ? gmwm::waveletVariance(raw.data() + nh, n - nh, ctx.rate) : w.raw;
  const gmwm::WaveletVariance wa = held_out ? gmwm::waveletVariance(x.data() + nh, n - nh, ctx.rate) : w.cleaned;
  const Model after_eval = withoutSin(held_out ? after_half : after_full);
  const auto tb = toStd(wb.tau), ta = toStd(wa.tau);
  const auto db = held_out ? halfDof(wb, w) : w.dof;
  const auto da = held_out ? halfDof(wa, w) : w.dof;
  const auto nub = wvOf(m0, tb), nua = wvOf(after_eval, ta);
  g.scales = wb.scales();
  g.added_params = added_params + 2 * static_cast<int>(lines);
  g.objective_before = m0.empty() ? kNaN : gmwm::objective(m0, wb);
  g.objective_after = after_eval.empty() ? kNaN : gmwm::objective(after_eval, wa);
  g.deviance_before = wvDeviance(toStd(wb.wv), nub, db);
  g.deviance_after = wvDeviance(toStd(wa.wv), nua, da);
  g.outside_before = countOutside(checkScales(wb, nub, db, w.p_thr, {}, {}));
  g.outside_after = countOutside(checkScales(wa, nua, da, w.p_thr, {}, {}));
  pairedScaleTest(toStd(wb.wv), nub, db, toStd(wa.wv), nua, da, &g.z, &g.p_value);
  g.test = std::string("one-sided paired z test over the ") + std::to_string(g.scales) + " " +
           (held_out ? "held-out (second-half)" : "whole-record") +
           " scales of the per-scale chi-square deviance, before minus after (scales are correlated: p is approximate)";
  const bool dev_better = g.deviance_after < g.deviance_before;
  const bool obj_better = !(g.objective_after >= g.objective_before);  // NaN (empty model) counts as not worse
  g.direction = dev_better && obj_better ? "better" : (!dev_better && !obj_better ? "worse" : "mixed");
  g.significant = dev_better && obj_better && g.p_value < 0.05;
  return g;
}

/// One channel through the pipeline of diagnosis.hpp.
ChannelDiagnosis diagnoseChannel(Shared& sh, int ci) {
  const ChannelContext ctx = channelContext(sh, ci);
  ChannelDiagnosis cd;
  cd.name = ctx.name;
  cd.model_before = ctx.m0;
  // The record with its mean removed: `raw` as measured, `x` as steps 1-3 clean it.
  const std::vector<double> raw = withoutMean(sh.data->channels[ci].x);
  std::vector<double> x = raw;
  // 1. Outlier events.
  const bool gaussian = removeOutliers(ctx, x, cd);
  sh.tick(ctx.name + ": outliers");
  // 2. Spectral lines.
  const std::vector<detect::SpectralLine> lines = removeLines(ctx, x, cd);
  sh.tick(ctx.name + ": spectrum");
  // 3. Level shifts and knocks.
  const bool outliers_or_lines = !cd.findings.empty();
  const auto wv_pre = gmwm::waveletVariance(x.data(), ctx.n, ctx.rate);
  ShiftsLeft shifts_left;
  const bool shifts_or_knocks = gaussian && removeLevelShifts(ctx, wv_pre, x, cd, shifts_left);
  sh.tick(ctx.name + ": level shifts");
  // 4. The WV against the model, then the cause of the broadband misfit;
  // then the shifts a random walk took up in step 3, against what it found.
  const WvCheck w = checkWv(sh, ctx, raw, x, wv_pre, outliers_or_lines, shifts_or_knocks, cd);
  const std::vector<Candidate> found = searchCauses(ctx, x, w, cd);
  const std::vector<Finding> left = shiftsTheSearchLeft(ctx, x, shifts_left, merged(ctx.m0n, found));
  cd.findings.insert(cd.findings.end(), left.begin(), left.end());
  // 5. The extension.
  const int added_params = extendModel(ctx, x, w, found, lines, cd);
  for (const ScaleCheck& sc : cd.scales_after) {
    // material: a factor 2 off (a sigma off by 1.4x) or a CI width beyond the CI
    // (an overstated slow term widens the CI far more upward than downward)
    const bool material = std::abs(sc.ci_widths) >= 1.0 || !(sc.ratio > 0.5 && sc.ratio < 2.0);
    if (!sc.significant || !material) continue;
    auto& u = cd.unexplained;
    if (u.scales++ == 0) u.tau_lo_s = sc.tau_s;
    u.tau_hi_s = sc.tau_s;
    if (!(std::abs(std::log(u.ratio)) >= std::abs(std::log(sc.ratio)))) u.ratio = sc.ratio;
  }
  cd.adequate = cd.findings.empty() && cd.unexplained.scales == 0;
  // 6. The gain, held out.
  cd.gain = heldOutGain(ctx, raw, x, w, cd.model_after, cd.model_after_half, added_params, lines.size());
  sh.tick(ctx.name + ": model extension");
  return cd;
}

/// Group per-channel outlier events and level shifts that happen at the same
/// time on two or more channels into Diagnosis::events.
void groupEvents(Diagnosis& d) {
  struct Item {
    int ch;
    int finding;  // level shift finding index, -1 for an outlier event
    double t, dur, size;
  };
  const double record = d.samples / d.rate_hz;
  for (Cause cause : {Cause::Outliers, Cause::LevelShift}) {
    std::vector<Item> items;
    for (std::size_t c = 0; c < d.channels.size(); ++c) {
      const auto& cd = d.channels[c];
      if (cause == Cause::Outliers)
        for (const auto& e : cd.outlier_events) items.push_back({static_cast<int>(c), -1, e.t_s, e.duration_s, e.size});
      else
        for (std::size_t i = 0; i < cd.findings.size(); ++i)
          if (cd.findings[i].cause == Cause::LevelShift)
            items.push_back({static_cast<int>(c), static_cast<int>(i), cd.findings[i].get("t_s"), 0.0,
                             cd.findings[i].get("size")});
    }
    std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) { return a.t < b.t; });
    // Same event: starts within the tolerance of the group's end.
    const double tol = cause == Cause::Outliers ? std::max(0.05, 5.0 / d.rate_hz)
                                                : std::max(2.0 / d.rate_hz, 0.005 * record);
    for (std::size_t i = 0; i < items.size();) {
      std::size_t j = i;
      double end = items[i].t + items[i].dur;
      while (j + 1 < items.size() && items[j + 1].t <= end + tol) {
        ++j;
        end = std::max(end, items[j].t + items[j].dur);
      }
      Event ev;
      ev.cause = cause;
      ev.t_s = items[i].t;
      ev.duration_s = end - items[i].t;
      for (std::size_t q = i; q <= j; ++q) {
        const std::string& name = d.channels[items[q].ch].name;
        if (std::find(ev.channels.begin(), ev.channels.end(), name) == ev.channels.end()) {
          ev.channels.push_back(name);
          ev.sizes.push_back(items[q].size);
        }
      }
      if (ev.channels.size() >= 2) {
        const int idx = static_cast<int>(d.events.size());
        for (std::size_t q = i; q <= j; ++q) {
          auto& cd = d.channels[items[q].ch];
          if (items[q].finding >= 0) cd.findings[items[q].finding].event = idx;
          else
            for (auto& f : cd.findings)
              if (f.cause == Cause::Outliers) f.event = idx;  // the channel's outlier finding
        }
        d.events.push_back(ev);
      }
      i = j + 1;
    }
  }
  std::sort(d.events.begin(), d.events.end(), [](const Event& a, const Event& b) { return a.t_s < b.t_s; });
}

}  // namespace

void checkDiagnoseOptions(const DiagnoseOptions& opt, std::size_t channels, std::size_t samples) {
  if (!(opt.alpha > 0 && opt.alpha < 0.5))
    throw Error("diagnose: alpha must be in (0, 0.5), got " + std::to_string(opt.alpha));
  if (opt.simulations < 0 || opt.simulations == 1 || opt.simulations > limits::kMaxMonteCarloRuns)
    throw Error("diagnose: --simulations must be 0 or in [2, " + std::to_string(limits::kMaxMonteCarloRuns) +
                "], got " + std::to_string(opt.simulations));
  // Work of the model's simulations, estimated before they start (README
  // "Ranges and budgets"): simulated samples over channels and simulations.
  const double work = double(opt.simulations) * double(channels) * double(samples);
  limits::checkBudget({{"diagnose: --simulations " + std::to_string(opt.simulations), "the model's simulations", work,
                        limits::kDefaultSimulatedSampleBudget, "simulated samples",
                        "simulations x " + std::to_string(channels) + " channels x " + std::to_string(samples) +
                            " samples",
                        "lower --simulations"}},
                      opt.allow_large);
}

Diagnosis diagnose(const ImuSeries& data, const stochastic::ImuModel& model,
                   const DiagnoseOptions& opt) {
  if (data.channels.empty()) throw Error(data.source + ": no IMU channel to diagnose");
  const std::size_t n = data.size();
  if (n < 4096)
    throw Error(data.source + ": " + std::to_string(n) +
                " samples; diagnose needs at least 4096 (two halves of 2048) for its "
                "held-out comparison and spectrum");
  if (!(data.rate_hz > 0)) throw Error(data.source + ": sampling rate must be > 0");
  checkDiagnoseOptions(opt, data.channels.size(), n);
  for (const auto& c : data.channels) {
    if (c.x.size() != n) throw Error(data.source + ": channel " + c.name + " has a different length");
    for (std::size_t k = 0; k < c.x.size(); ++k)
      if (!std::isfinite(c.x[k]))
        throw Error(data.source + ": channel " + c.name + ": sample " + std::to_string(k) +
                    " is not finite");
  }
  const auto t0 = std::chrono::steady_clock::now();
  Diagnosis d;
  d.source = data.source;
  d.rate_hz = data.rate_hz;
  d.samples = n;
  d.options = opt;
  d.model_before = model;
  d.model_before = stochastic::atRate(model, data.rate_hz, &d.notices);
  Shared sh;
  sh.data = &data;
  sh.model = &d.model_before;
  sh.opt = &opt;
  const double C = static_cast<double>(data.channels.size());
  sh.per_channel = {0.4 * opt.alpha / C, 0.2 * opt.alpha / C, 0.2 * opt.alpha / C,
                    0.2 * opt.alpha / C};
  sh.channels = C;
  sh.total_units = static_cast<int>(data.channels.size()) * (opt.simulations + 4);
  d.channels.resize(data.channels.size());
  // Channels in parallel; a failure names its channel (the lowest one that failed).
  parallelFor(data.channels.size(), static_cast<unsigned>(std::max(opt.threads, 0)), [&](std::size_t i) {
    try {
      d.channels[i] = diagnoseChannel(sh, static_cast<int>(i));
    } catch (const Error& e) {
      throw Error(data.source + ": channel " + data.channels[i].name + ": " + e.what());
    }
  });
  d.model_after = d.model_before;
  d.adequate = true;
  for (const auto& c : d.channels) {
    d.model_after.forChannel(c.name) = c.model_after;
    d.adequate = d.adequate && c.adequate;
  }
  d.model_after.source = "diagnose";
  groupEvents(d);
  d.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return d;
}

}  // namespace navimpact::analysis
