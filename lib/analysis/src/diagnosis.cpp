// navimpact diagnose: what a simulation with the user's model gets wrong, why,
// and what an extended model gains (see diagnosis.hpp for the method).
#include "navimpact/analysis/diagnosis.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>
#include <tuple>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>

#include "diagnosis_internal.hpp"
#include "diagnosis_slow.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/golden_section.hpp"
#include "navimpact/core/parallel.hpp"
#include "navimpact/detect/change_points.hpp"
#include "navimpact/detect/lines.hpp"
#include "navimpact/detect/null_model.hpp"
#include "navimpact/detect/outliers.hpp"
#include "navimpact/detect/step_test.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"
#include "navimpact/gmwm/estimator.hpp"
#include "navimpact/stochastic/block_likelihood.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/process_kind.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

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

namespace {

using namespace detail;

/// Per-scale comparison of a measured WV with a model under chi-square(dof).
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
    boost::math::chi_squared chi(dof[j]);
    s.ci_low = nu_m[j] * boost::math::quantile(chi, 0.025) / dof[j];
    s.ci_high = nu_m[j] * boost::math::quantile(chi, 0.975) / dof[j];
    s.ratio = s.measured / s.model;
    const double stat = dof[j] * s.ratio;
    const double lo = boost::math::cdf(chi, stat);
    const double hi = boost::math::cdf(boost::math::complement(chi, stat));
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

int countSignificant(const std::vector<ScaleCheck>& s) {
  int c = 0;
  for (const auto& x : s) c += x.significant ? 1 : 0;
  return c;
}
int countOutside(const std::vector<ScaleCheck>& s) {
  int c = 0;
  for (const auto& x : s) c += x.outside95 ? 1 : 0;
  return c;
}

const char* shapeWords(ProcessKind k) {
  switch (k) {
    case ProcessKind::WN: return "falls as 1/tau, the shape of white noise";
    case ProcessKind::QN: return "falls as 1/tau^2, the shape of quantization noise";
    case ProcessKind::RW: return "grows as tau, the shape of a random walk";
    case ProcessKind::DR: return "grows as tau^2, the shape of a drift";
    case ProcessKind::GM: return "is peaked, the shape of a Gauss-Markov process";
    case ProcessKind::SIN: return "oscillates, the shape of a sinusoid";
  }
  return "";
}

// --------------------------------------------------------------------------

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

std::string scaleRange(double lo, double hi) {
  if (!(hi > lo * 1.0001)) return "tau = " + formatNumber(lo, 3) + " s";
  return "tau = " + formatNumber(lo, 3) + "–" + formatNumber(hi, 3) + " s";
}

/// Largest |WV change| of a model change relative to the CI width of the
/// measured WV at that scale (a finding must reach 1 somewhere).
double wvChangeInCiWidths(const std::vector<ScaleCheck>& chk, const std::vector<double>& nu_before,
                          const std::vector<double>& nu_after) {
  double best = 0;
  for (std::size_t j = 0; j < chk.size(); ++j) {
    const double w = chk[j].ci_high - chk[j].ci_low;
    if (w > 0) best = std::max(best, std::abs(nu_after[j] - nu_before[j]) / w);
  }
  return best;
}

/// Scales where a change of model explains the misfit: outside the per-scale
/// 95 % CI before, with the log misfit reduced by more than half.
void explainedRange(const std::vector<ScaleCheck>& chk, const std::vector<double>& nu_before,
                    const std::vector<double>& nu_after, double* lo, double* hi, double* max_ratio,
                    int* count) {
  *lo = kNaN;
  *hi = kNaN;
  *max_ratio = 1;
  *count = 0;
  for (std::size_t j = 0; j < chk.size(); ++j) {
    const double mb = std::abs(std::log(chk[j].measured / std::max(nu_before[j], 1e-300)));
    const double ma = std::abs(std::log(chk[j].measured / std::max(nu_after[j], 1e-300)));
    if (!chk[j].outside95 || !(mb - ma > 0.5 * mb)) continue;
    if (std::isnan(*lo)) *lo = chk[j].tau_s;
    *hi = chk[j].tau_s;
    ++*count;
    const double r = chk[j].ratio;
    if (std::abs(std::log(r)) > std::abs(std::log(*max_ratio))) *max_ratio = r;
  }
}

Finding broadbandFinding(const std::string& ch, const Candidate& c, const Model& before,
                         const std::vector<ScaleCheck>& chk, const std::vector<double>& tau,
                         double rate) {
  Finding f;
  f.channel = ch;
  f.cause = causeOf(c.kind);
  const Model after = applyCandidate(before, c);
  const auto nb = wvOf(before, tau), na = wvOf(after, tau);
  double lo, hi, ratio;
  int count;
  explainedRange(chk, nb, na, &lo, &hi, &ratio, &count);
  f.range_key = "scales_s";
  f.range_lo = lo;
  f.range_hi = hi;
  const std::string unit = channelUnit(ch);
  Process p = c.proc;
  std::ostringstream ex;
  const bool above = ratio >= 1;
  f.direction = (c.retune && c.scale < 1) ? "overstated" : "missing";
  const double factor = above ? ratio : 1.0 / ratio;
  if (count > 0)
    ex << "the measured WV is "
       << (factor < 1.5  // a small excess as a percentage ("1x" says nothing)
               ? formatNumber(100.0 * std::abs(ratio - 1.0), 2) + " % "
               : formatNumber(factor, 2) + "x ")
       << (above ? "above" : "below") << " the model at " << scaleRange(lo, hi) << " ("
       << count << " scale" << (count > 1 ? "s" : "") << " outside the 95 % CI); ";
  switch (c.kind) {
    case ProcessKind::WN: f.params = {{"sigma", p.sigma}}; break;
    case ProcessKind::QN: f.params = {{"Q", p.Q}}; break;
    case ProcessKind::RW: f.params = {{"gamma", p.gamma}}; break;
    case ProcessKind::DR: f.params = {{"omega", p.omega}}; break;
    case ProcessKind::GM:
      f.params = {{"sigma", p.sigma}, {"T", p.T}};
      f.T_interval_s = std::make_pair(c.T_lo, c.T_hi);
      f.intervals.push_back({"T", {c.T_lo, c.T_hi}});
      break;
    case ProcessKind::SIN: f.params = {{"amplitude", p.amp}, {"freq_hz", p.freq_hz}}; break;
  }
  if (c.kind != ProcessKind::GM && std::isfinite(c.p_lo))
    f.intervals.push_back({f.params.front().first, {c.p_lo, c.p_hi}});
  if (c.retune) {
    Process old = before.terms[c.term];
    ex << "the model's " << stochastic::formatTerms({old}, 3) << " is "
       << (c.scale < 1 ? "overstated" : "understated") << "; the data fit "
       << stochastic::formatTerms({p}, 3);
  } else {
    ex << "the excess " << shapeWords(c.kind);
    if (c.kind == ProcessKind::GM)
      ex << " with T = " << formatNumber(p.T, 3) << " s (95 % interval " << formatNumber(c.T_lo, 3) << "–"
         << formatNumber(c.T_hi, 3) << " s), sigma = " << formatNumber(p.sigma, 3) << " " << unit;
    else
      ex << ": " << stochastic::formatTerms({p}, 3) << " (" << unit << ", per sample at "
         << formatNumber(rate, 4) << " Hz)";
  }
  ex << ".";
  f.explanation = ex.str();
  f.action = c.retune ? "retune it in the model (model_extended.yaml)"
                      : "add it to the model (model_extended.yaml); the filter takes it as " +
                            std::string(c.kind == ProcessKind::WN || c.kind == ProcessKind::QN
                                            ? "measurement noise"
                                            : "error state(s)");
  return f;
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


ChannelDiagnosis diagnoseChannel(Shared& sh, int ci) {
  const ImuChannel& chan = sh.data->channels[ci];
  const DiagnoseOptions& opt = *sh.opt;
  const double rate = sh.data->rate_hz;
  const std::size_t n = chan.x.size();
  const double record = static_cast<double>(n) / rate;
  const double t0 = sh.data->t0_s;
  ChannelDiagnosis cd;
  cd.name = chan.name;
  cd.model_before = sh.model->forChannel(chan.name);
  const Model& m0 = cd.model_before;
  const Model m0n = withoutSin(m0);
  const Budget& B = sh.per_channel;
  const std::string unit = channelUnit(cd.name);
  ChannelContext ctx;
  ctx.name = cd.name;
  ctx.unit = unit;
  ctx.index = ci;
  ctx.rate = rate;
  ctx.n = n;
  ctx.record = record;
  ctx.t0 = t0;
  ctx.m0 = m0;
  ctx.m0n = m0n;
  ctx.B = B;
  ctx.channels = sh.channels;
  ctx.max_terms = opt.max_terms;
  ctx.simulations = opt.simulations;
  ctx.seed = opt.seed;

  std::vector<double> x = chan.x;
  double mean = 0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  for (double& v : x) v -= mean;
  const std::vector<double> raw = x;

  removeOutliers(ctx, x, cd);
  sh.tick(cd.name + ": outliers");
  const std::vector<detect::SpectralLine> lines = removeLines(ctx, x, cd);
  sh.tick(cd.name + ": spectrum");
  const auto wv_pre = gmwm::waveletVariance(x.data(), n, rate);
  const std::vector<double> tau = toStd(wv_pre.tau);
  const std::size_t findings_pre = cd.findings.size();
  const bool x_after_pre_changed = removeLevelShifts(ctx, wv_pre, x, cd);
  sh.tick(cd.name + ": level shifts");

  // 4. WV of the raw and cleaned record vs the model, with simulations.
  // (A WV is recomputed only where the record changed since wv_pre.)
  const bool changed_before_pre = findings_pre > 0;  // outliers or lines removed
  const bool changed_after_pre = x_after_pre_changed;
  const auto wv_raw = changed_before_pre ? gmwm::waveletVariance(raw.data(), n, rate) : wv_pre;
  const auto wv_cl = changed_after_pre ? gmwm::waveletVariance(x.data(), n, rate) : wv_pre;
  const int J = wv_raw.scales();
  const auto nu0 = wvOf(m0, tau);
  std::vector<double> env_lo(J, std::numeric_limits<double>::infinity()), env_hi(J, 0.0);
  std::vector<double> dof = toStd(wv_raw.eta);
  if (!m0.empty() && opt.simulations >= 2) {
    std::vector<double> s1(J, 0.0), s2(J, 0.0);
    for (int s = 0; s < opt.simulations; ++s) {
      const auto sim = stochastic::simulate(
          m0, n, stochastic::deriveSeed(opt.seed, 1000u * static_cast<unsigned>(ci) + s));
      const auto w = gmwm::waveletVariance(sim.data(), n, rate);
      for (int j = 0; j < J && j < w.scales(); ++j) {
        env_lo[j] = std::min(env_lo[j], w.wv(j));
        env_hi[j] = std::max(env_hi[j], w.wv(j));
        const double r = nu0[j] > 0 ? w.wv(j) / nu0[j] : 0;
        s1[j] += r;
        s2[j] += r * r;
      }
      sh.tick(cd.name + ": simulations");
    }
    // Moment-matched dof of the simulated ratios (var of chi2_eta / eta = 2 / eta),
    // used where fewer than eta (the theory would be over-confident there).
    const double S = opt.simulations;
    for (int j = 0; j < J; ++j) {
      const double m = s1[j] / S, v = (s2[j] - S * m * m) / (S - 1);
      if (v > 0 && m > 0) dof[j] = std::max(1.0, std::min(dof[j], 2.0 * m * m / v));
    }
  } else {
    env_lo.clear();
    env_hi.clear();
    sh.tick(cd.name + ": simulations", opt.simulations);
  }
  const double p_thr = B.wv / J;  // two-sided p-value vs alpha / J (Bonferroni over scales)
  cd.wv_threshold_p = p_thr;
  cd.scales = checkScales(wv_raw, nu0, dof, p_thr, env_lo, env_hi);
  // The WV test on the cleaned record against the model with its lines.
  const auto nu0n = wvOf(m0n, tau);
  auto chk_cl = checkScales(wv_cl, nu0n, dof, p_thr, env_lo, env_hi);

  // 5. Cause of the broadband misfit: candidates on the first half, refit on all.
  const std::size_t nh = n / 2;
  const auto wv_h1 = gmwm::waveletVariance(x.data(), nh, rate);
  const auto wv_h2c = gmwm::waveletVariance(x.data() + nh, n - nh, rate);
  const auto wv_h2r = gmwm::waveletVariance(raw.data() + nh, n - nh, rate);
  auto halfDof = [&](const gmwm::WaveletVariance& w) {
    std::vector<double> d(w.scales());
    for (int j = 0; j < w.scales(); ++j) {
      const double ratio = wv_raw.eta(j) > 0 ? dof[j] / wv_raw.eta(j) : 1.0;
      d[j] = std::max(1.0, w.eta(j) * std::min(1.0, ratio));
    }
    return d;
  };
  WvData full{tau, toStd(wv_cl.wv), dof, static_cast<double>(n)};
  WvData h1{toStd(wv_h1.tau), toStd(wv_h1.wv), halfDof(wv_h1), static_cast<double>(nh)};

  Model m_full = m0n, m_half = m0n;
  int added_params = 0;
  // Block means of the cleaned record for the exact likelihood that decides
  // between the slow explanations (random walk, drift, long Gauss-Markov),
  // which differ only at the coarsest WV scales where it has few dof.
  const std::size_t blk = std::max<std::size_t>(1, n / 512);
  const std::vector<double> yb = stochastic::blockMeans(x.data(), n, blk);
  auto isSlow = [&](const Candidate& c) {
    if (c.kind == ProcessKind::RW || c.kind == ProcessKind::DR) return true;
    return c.kind == ProcessKind::GM && !c.retune && c.proc.T * rate >= 4.0 * static_cast<double>(blk);
  };
  // The new terms of an extension that are not slow: extensions with the
  // same such part differ only in their slow explanation.
  auto fastPart = [&](const Extension& e) {
    std::vector<std::tuple<int, int, int>> k;
    for (std::size_t i = e.terms.size() - e.added; i < e.terms.size(); ++i)
      if (!isSlow(e.terms[i])) k.emplace_back(e.terms[i].retune, e.terms[i].term, static_cast<int>(e.terms[i].kind));
    std::sort(k.begin(), k.end());
    return k;
  };
  auto hasSlow = [&](const Extension& e) {
    for (std::size_t i = e.terms.size() - e.added; i < e.terms.size(); ++i)
      if (isSlow(e.terms[i])) return true;
    return false;
  };
  // Regressors of the block means: the mean, a trend when the model has a
  // drift, and optionally a level shift at block boundary @p step.
  auto blockRegressors = [&](bool trend, std::size_t step) {
    Eigen::MatrixXd X(static_cast<Eigen::Index>(yb.size()), 1 + (trend ? 1 : 0) + (step > 0 ? 1 : 0));
    for (std::size_t k = 0; k < yb.size(); ++k) {
      const auto r = static_cast<Eigen::Index>(k);
      X(r, 0) = 1.0;
      if (trend) X(r, 1) = (static_cast<double>(k) + 0.5) / static_cast<double>(yb.size()) - 0.5;
      if (step > 0) X(r, X.cols() - 1) = k >= step ? 1.0 : 0.0;
    }
    return X;
  };
  // AIC on the exact likelihood of the block means of an extension: only its
  // new terms profiled (a drift's slope is the GLS trend), their parameters
  // counted. NaN when the likelihood cannot be evaluated.
  auto exactAic = [&](const Extension& e, double* loglik) {
    Model mc = withoutSin(assemble(m0n, e.terms));
    const Eigen::MatrixXd X = blockRegressors(mc.count(ProcessKind::DR) > 0, 0);
    std::vector<int> own;
    for (std::size_t q = e.terms.size() - e.added; q < e.terms.size(); ++q)
      if (e.terms[q].kind != ProcessKind::DR) own.push_back(assembledIndex(m0n, e.terms, q));
    if (own.empty()) own.push_back(-1);
    try {
      const double l = stochastic::profileBlockLogLikelihood(mc, yb, blk, X, own);
      *loglik = l;
      return -2.0 * l + penalty(e.terms, e.terms.size() - e.added);
    } catch (const Error&) {
      return kNaN;
    }
  };
  // The best single level shift on top of @p terms (block boundaries in the
  // middle 90 %, every 4th then refined): exact AIC with the shift's size and
  // time as its two parameters; *t_s, *size where it sits.
  auto bestShiftAic = [&](const std::vector<Candidate>& terms, double* t_s, double* size) {
    const Model mb = withoutSin(assemble(m0n, terms));
    const bool trend = mb.count(ProcessKind::DR) > 0;
    const std::size_t nb = yb.size(), k0 = std::max<std::size_t>(1, nb / 20), k1 = nb - k0;
    double best_l = -std::numeric_limits<double>::infinity();
    std::size_t best_k = 0;
    double best_size = kNaN;
    auto at = [&](std::size_t k) {
      try {
        const auto r = stochastic::blockLogLikelihood(mb, yb, blk, blockRegressors(trend, k));
        if (r.loglik > best_l) {
          best_l = r.loglik;
          best_k = k;
          best_size = r.beta(r.beta.size() - 1);
        }
      } catch (const Error&) {
      }
    };
    for (std::size_t k = k0; k <= k1; k += 4) at(k);
    const std::size_t c = best_k;
    for (std::size_t k = c > k0 + 3 ? c - 3 : k0; k <= std::min(k1, c + 3); ++k)
      if (k != c) at(k);
    if (best_k == 0) return kNaN;
    *t_s = t0 + static_cast<double>(best_k * blk) / rate;
    *size = best_size;
    return -2.0 * best_l + 4.0;
  };
  auto causesOf = [&](const Extension& e) {
    std::vector<std::string> c;
    for (std::size_t q = e.terms.size() - e.added; q < e.terms.size(); ++q) c.push_back(causeName(causeOf(e.terms[q].kind)));
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
    std::string j;
    for (const auto& x : c) j += (j.empty() ? "" : "+") + x;
    return j;
  };
  const WvTest wt = wvTest(full, p_thr);
  std::vector<Candidate> S;          // the terms found, backfitted on the whole record
  std::vector<std::size_t> found_at;  // S[i]'s finding in cd.findings
  double cur_crit = wvDeviance(full.nu, wvOf(m0n, tau), full.dof);
  auto chk = chk_cl;
  while (static_cast<int>(S.size()) < opt.max_terms && countSignificant(chk) > 0) {
    // Cause chosen on the whole cleaned record (all scales: the coarsest
    // ones separate random walk, drift and long Gauss-Markov), by AIC over
    // every extension by one term or two jointly fitted ones.
    const auto ext = extensions(m0n, S, full, wt, opt.max_terms - static_cast<int>(S.size()));
    std::vector<int> order, order_all;
    for (std::size_t i = 0; i < ext.size(); ++i)
      if (ext[i].valid) (ext[i].needed ? order : order_all).push_back(static_cast<int>(i));
      else if (ext[i].open_top) order_all.push_back(static_cast<int>(i));
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return ext[a].crit < ext[b].crit; });
    if (order.empty() || !(ext[order[0]].crit < cur_crit)) break;
    int best = order[0];
    int second = order.size() > 1 ? order[1] : -1;
    // Slow explanations compared by the exact Gaussian likelihood of the block
    // means (the new terms' variances profiled, a drift's slope by GLS), AIC.
    std::string exact_evidence;
    std::vector<std::pair<double, int>> ranked_exact;  // (exact AIC, extension) when the slow ones were ranked
    std::vector<std::pair<double, int>> excluded;      // larger sets the nested test kept out
    if (hasSlow(ext[best]) && yb.size() >= 16) {
      const auto key = fastPart(ext[best]);
      std::vector<std::pair<double, int>> ranked;
      std::vector<double> loglik(ext.size(), kNaN);
      std::vector<int> pool = order;
      pool.insert(pool.end(), order_all.begin(), order_all.end());
      for (int i : pool) {
        const Extension& e = ext[i];
        if (!hasSlow(e) || fastPart(e) != key) continue;
        double l = kNaN;
        const double aic = exactAic(e, &l);
        if (!std::isfinite(aic)) continue;
        loglik[i] = l;
        ranked.push_back({aic, i});
      }
      std::stable_sort(ranked.begin(), ranked.end());
      // The reference is the best explanation with the fewest terms whose
      // GMs the WV bounds (a GM whose WV profile interval of T reaches
      // record/5 competes by AIC). One with more terms that the WV did not
      // need replaces it only when it contains the reference's terms and its
      // exact likelihood ratio against the reference rejects at 1 %
      // (nested: chi-square with the added parameters as dof).
      {
        int simple = -1;
        for (const auto& r : ranked)
          if (!ext[r.second].open_top && (simple < 0 || ext[r.second].added < ext[simple].added)) simple = r.second;
        if (simple >= 0) {
          std::vector<std::pair<double, int>> kept;
          for (const auto& r : ranked) {
            const Extension& e = ext[r.second];
            auto contains = [&](const Extension& big, const Extension& small) {
              for (std::size_t q = small.terms.size() - small.added; q < small.terms.size(); ++q) {
                bool in = false;
                for (std::size_t k = big.terms.size() - big.added; k < big.terms.size(); ++k)
                  in = in || (big.terms[k].kind == small.terms[q].kind && big.terms[k].retune == small.terms[q].retune &&
                              big.terms[k].term == small.terms[q].term);
                if (!in) return false;
              }
              return true;
            };
            if (e.added > ext[simple].added && !e.needed) {
              if (!contains(e, ext[simple])) continue;
              const double dof_lr = std::max(1.0, (penalty(e.terms, e.terms.size() - e.added) -
                                                   penalty(ext[simple].terms, ext[simple].terms.size() - ext[simple].added)) / 2.0);
              const double lr = 2.0 * (loglik[r.second] - loglik[simple]);
              if (!(lr > boost::math::quantile(boost::math::complement(boost::math::chi_squared(dof_lr), 0.01)))) {
                excluded.push_back(r);
                continue;
              }
            }
            kept.push_back(r);
          }
          ranked = kept;
        }
      }
      ranked_exact = ranked;
      if (ranked.size() >= 2) {
        const int wv_best = best;
        best = ranked[0].second;
        second = ranked[1].second;
        exact_evidence = "; among the slow explanations the exact likelihood of " + std::to_string(yb.size()) +
                         " block means (variances profiled) gives AIC " + formatNumber(ranked[0].first, 7) + " against " +
                         formatNumber(ranked[1].first, 7) + " for " + newTermsText(ext[second]) +
                         (best != wv_best ? " (the WV alone preferred " + newTermsText(ext[wv_best]) + ")" : std::string());
      }
    }
    if (second == best) second = -1;
    if (second < 0)
      for (int i : order)
        if (i != best) {
          second = i;
          break;
        }
    // The slow decision on the exact likelihood of the block means
    // (diagnosis_slow.hpp): it may replace the WV's slow terms by the slow
    // explanation the block means prefer, and it judges the runner-up.
    Extension chosen = ext[best];
    slow::Choice sc;
    if (hasSlow(chosen) && yb.size() >= 16) {
      slow::Problem sp;
      std::vector<Candidate> fast_terms(chosen.terms.begin(), chosen.terms.end() - chosen.added);
      for (std::size_t q = chosen.terms.size() - chosen.added; q < chosen.terms.size(); ++q) {
        const Candidate& c = chosen.terms[q];
        if (isSlow(c)) {
          sp.wv_slow.push_back(causeOf(c.kind));
        } else {
          fast_terms.push_back(c);
          sp.fast_causes.push_back(causeName(causeOf(c.kind)));
        }
      }
      sp.base = withoutSin(assemble(m0n, fast_terms));
      sp.fast_pen = penalty(fast_terms, S.size());
      sp.wv_start = withoutSin(assemble(m0n, chosen.terms));
      for (std::size_t q = chosen.terms.size() - chosen.added; q < chosen.terms.size(); ++q)
        if (isSlow(chosen.terms[q]) && chosen.terms[q].kind != ProcessKind::DR)
          sp.wv_own.push_back(assembledIndex(m0n, chosen.terms, q));
      sp.wv_pen = penalty(chosen.terms, chosen.terms.size() - chosen.added);
      sp.wv_text = newTermsText(chosen);
      sp.y = &yb;
      sp.block = blk;
      sp.rate_hz = rate;
      sp.record_s = record;
      sp.seed = stochastic::deriveSeed(opt.seed, 7000000u + 1000u * static_cast<unsigned>(ci) + static_cast<unsigned>(S.size()));
      sc = slow::decide(sp);
      if (sc.decided_here && sc.swapped) {
        Extension e;
        e.terms = fast_terms;
        for (const auto& t : sc.terms) {
          Candidate c;
          c.kind = t.proc.kind;
          c.proc = t.proc;
          c.params = c.kind == ProcessKind::GM ? 2 : 1;
          if (c.kind == ProcessKind::GM) {
            c.T_lo = t.lo;
            c.T_hi = t.hi;
            c.T_hi_open = c.T_top_only = t.open_top;
          } else {
            c.p_lo = t.lo;
            c.p_hi = t.hi;
          }
          e.terms.push_back(c);
        }
        e.added = static_cast<int>(e.terms.size() - S.size());
        e.deviance = wvDeviance(full.nu, wvOf(assemble(m0n, e.terms), tau), full.dof);
        e.crit = e.deviance + penalty(e.terms);
        e.valid = true;
        chosen = e;
      }
    }
    const Extension& win = chosen;
    const Model before = merged(m0n, S);
    const Model after = merged(m0n, win.terms);
    // A finding must change the WV by at least its CI width at some scale.
    if (win.added == 1 && wvChangeInCiWidths(chk, wvOf(before, tau), wvOf(after, tau)) < 1.0) break;
    double pmin = 1;
    for (const auto& s : chk) pmin = std::min(pmin, s.p_value);
    std::string evidence = "AIC " + formatNumber(win.crit, 5) +
                           (second >= 0 ? " against " + formatNumber(ext[second].crit, 5) + " for the runner-up, " + newTermsText(ext[second])
                                        : std::string(" (no other family fits)"));
    if (win.added == 2) {
      // Name the best one-term explanation the pair beat.
      int single = -1;
      for (int i : order)
        if (ext[i].added == 1) {
          single = i;
          break;
        }
      evidence += "; fitted jointly: " + newTermsText(win) +
                  (single >= 0 ? " against the best single term " + newTermsText(ext[single]) + " (AIC " +
                                     formatNumber(ext[single].crit, 5) + ", " + std::to_string(ext[single].significant) +
                                     " scale(s) still significant)"
                               : std::string()) +
                  (win.needed ? ", below every single term by more than the 1 % chi-square margin"
                              : ", both needed by the exact likelihood (nested likelihood ratio at 1 %)");
    }
    if (sc.decided_here) evidence = (sc.swapped ? "the WV's coarsest scales leave the slow explanations open" : evidence) + sc.evidence;
    else evidence += exact_evidence;
    // The runner-up naming other causes, on the criterion that chose (the
    // exact likelihood among the slow explanations, else the WV AIC), and a
    // single level shift against a slow explanation (a shift near its
    // detection limit that the shift test could not accept looks like a
    // random walk): decided only when the winner is lower by at least 2 in
    // AIC (below 2 both have substantial support; Burnham & Anderson 2002,
    // §2.6).
    std::string ru, ru_detail;
    double ru_margin = kNaN, ru_p = kNaN;
    int ru_draws = 0;
    bool ru_larger = false;  // the runner-up contains the winner (ru_p: its lead under the winner)
    {
      const std::string mine = causesOf(win);
      if (sc.decided_here) {
        // The slow decision (diagnosis_slow.hpp): its runner-up and bootstrap.
        ru = sc.runner_up;
        ru_detail = sc.runner_up_detail;
        ru_margin = sc.runner_up.empty() ? kNaN : sc.aic_margin;
        ru_p = sc.runner_up.empty() ? kNaN : sc.p;
        ru_draws = sc.draws;
        ru_larger = sc.larger;
      } else {
        for (int i : order)
          if (i != best && causesOf(ext[i]) != mine) {
            ru = causesOf(ext[i]);
            ru_detail = newTermsText(ext[i]) + " (WV deviance)";
            ru_margin = ext[i].crit - win.crit;
            break;
          }
      }
      if (hasSlow(win) && yb.size() >= 16) {
        double l_slow = kNaN, t_shift = kNaN, size_shift = kNaN;
        double aic_slow = kNaN;
        for (const auto& r : ranked_exact)
          if (r.second == best) aic_slow = r.first;
        if (!std::isfinite(aic_slow)) aic_slow = exactAic(win, &l_slow);
        const double aic_shift = bestShiftAic(S, &t_shift, &size_shift);
        // The shift is the runner-up when it is closer than the slow one (by
        // AIC, or, when the slow one was simulated and rejected, whenever it
        // is within the AIC margin of 2 that decides against a shift).
        const double shift_margin = aic_shift - aic_slow;
        const bool slow_open = std::isfinite(ru_p) && (ru_larger ? ru_p <= slow::kLevel : ru_p > slow::kLevel);
        const bool closer = std::isfinite(ru_p) ? !slow_open && shift_margin < 2.0
                                                : (!std::isfinite(ru_margin) || shift_margin < ru_margin);
        if (std::isfinite(aic_slow) && std::isfinite(aic_shift) && closer) {
          ru_p = kNaN;
          ru_draws = 0;
          ru = causeName(Cause::LevelShift);
          ru_detail = "a level shift of " + formatNumber(size_shift, 3) + " " + unit + " at t = " + formatNumber(t_shift, 6) +
                      " s (exact likelihood of " + std::to_string(yb.size()) + " block means: AIC " +
                      formatNumber(aic_shift, 7) + " against " + formatNumber(aic_slow, 7) + ")";
          ru_margin = aic_shift - aic_slow;
        }
      }
    }
    for (std::size_t q = win.terms.size() - win.added; q < win.terms.size(); ++q) {
      Finding nf;
      nf.channel = cd.name;
      nf.statistic = pmin;
      nf.threshold = p_thr;
      nf.p_value = std::min(1.0, pmin * J * sh.channels / 0.4);  // Bonferroni over scales and channels (WV share)
      nf.evidence = evidence;
      nf.runner_up = ru;
      nf.runner_up_detail = ru_detail;
      nf.aic_margin = ru_margin;
      nf.runner_up_p = ru_p;
      nf.runner_up_draws = ru_draws;
      nf.decided = ru.empty() || (std::isfinite(ru_p) ? (ru_larger ? ru_p > slow::kLevel : ru_p <= slow::kLevel)
                                                    : !(ru_margin < 2.0));
      cd.findings.push_back(nf);
      found_at.push_back(cd.findings.size() - 1);
    }
    S = win.terms;
    cur_crit = win.crit;
    chk = checkScales(wv_cl, wvOf(merged(m0n, S), tau), dof, p_thr, {}, {});
  }
  // Each finding as it stands in the joint fit: its parameters, intervals and
  // the misfit it explains given the other terms found.
  for (std::size_t i = 0; i < S.size(); ++i) {
    std::vector<Candidate> others;
    for (std::size_t q = 0; q < S.size(); ++q)
      if (q != i) others.push_back(S[q]);
    // The other terms as the model file has them (retune indices refer to
    // m0n's terms, which merged() leaves in place).
    const Model before = merged(m0n, others);
    const auto chk_i = checkScales(wv_cl, wvOf(before, tau), dof, p_thr, {}, {});
    Finding nf = broadbandFinding(cd.name, S[i], before, chk_i, tau, rate);
    Finding& f = cd.findings[found_at[i]];
    nf.statistic = f.statistic;
    nf.threshold = f.threshold;
    nf.p_value = f.p_value;
    nf.evidence = f.evidence;
    nf.runner_up = f.runner_up;
    nf.runner_up_detail = f.runner_up_detail;
    nf.aic_margin = f.aic_margin;
    nf.runner_up_p = f.runner_up_p;
    nf.runner_up_draws = f.runner_up_draws;
    nf.decided = f.decided;
    f = nf;
    added_params += S[i].params;
  }
  m_full = merged(m0n, S);
  {
    // The same terms on the first half, for the held-out gain.
    std::vector<Candidate> Sh = S;
    if (!Sh.empty()) backfit(m0n, Sh, h1);
    m_half = merged(m0n, Sh);
  }
  if (added_params > 0) {
    m_half = gmwmRefit(m_half, wv_h1, h1, &cd.refit_half);
    m_full = gmwmRefit(m_full, wv_cl, full, &cd.refit_full);
  }
  cd.scales_after = checkScales(wv_cl, wvOf(m_full, tau), dof, p_thr, {}, {});
  // The user's SIN terms and the lines found become SIN terms of the extension.
  for (const auto& p : m0.terms)
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
  cd.wv_cleaned = toStd(wv_cl.wv);
  cd.adequate = cd.findings.empty();

  // 6. Gain, held out: the user's model on the raw second half against the
  // first-half extension (its lines, outliers and steps removed with the
  // detectors' whole-record estimates) on the cleaned second half. Without a
  // fitted broadband term (cleaning or lines only) nothing was fitted to the
  // WV and the whole record is used.
  GainCheck& g = cd.gain;
  const bool held_out = added_params > 0;
  g.basis = held_out ? "second_half" : "full_record";
  const gmwm::WaveletVariance& wb = held_out ? wv_h2r : wv_raw;
  const gmwm::WaveletVariance& wa = held_out ? wv_h2c : wv_cl;
  const Model after_eval = withoutSin(held_out ? m_half : m_full);
  const auto tb = toStd(wb.tau), ta = toStd(wa.tau);
  const auto db = held_out ? halfDof(wb) : dof;
  const auto da = held_out ? halfDof(wa) : dof;
  const auto nub = wvOf(m0, tb), nua = wvOf(after_eval, ta);
  g.scales = wb.scales();
  g.added_params = added_params + 2 * static_cast<int>(lines.size());
  g.objective_before = m0.empty() ? kNaN : gmwm::objective(m0, wb);
  g.objective_after = after_eval.empty() ? kNaN : gmwm::objective(after_eval, wa);
  g.deviance_before = wvDeviance(toStd(wb.wv), nub, db);
  g.deviance_after = wvDeviance(toStd(wa.wv), nua, da);
  g.outside_before = countOutside(checkScales(wb, nub, db, p_thr, {}, {}));
  g.outside_after = countOutside(checkScales(wa, nua, da, p_thr, {}, {}));
  pairedScaleTest(toStd(wb.wv), nub, db, toStd(wa.wv), nua, da, &g.z, &g.p_value);
  g.test = std::string("one-sided paired z test over the ") + std::to_string(g.scales) + " " +
           (held_out ? "held-out (second-half)" : "whole-record") +
           " scales of the per-scale chi-square deviance, before minus after (scales are correlated: p is approximate)";
  const bool dev_better = g.deviance_after < g.deviance_before;
  const bool obj_better = !(g.objective_after >= g.objective_before);  // NaN (empty model) counts as not worse
  g.direction = dev_better && obj_better ? "better" : (!dev_better && !obj_better ? "worse" : "mixed");
  g.significant = dev_better && obj_better && g.p_value < 0.05;
  sh.tick(cd.name + ": model extension");
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

Diagnosis diagnose(const ImuSeries& data, const stochastic::ImuModel& model,
                   const DiagnoseOptions& opt) {
  if (!(opt.alpha > 0 && opt.alpha < 0.5))
    throw Error("diagnose: alpha must be in (0, 0.5), got " + std::to_string(opt.alpha));
  if (opt.simulations < 0 || opt.simulations == 1)
    throw Error("diagnose: simulations must be 0 or >= 2, got " +
                std::to_string(opt.simulations));
  if (data.channels.empty()) throw Error(data.source + ": no IMU channel to diagnose");
  const std::size_t n = data.size();
  if (n < 4096)
    throw Error(data.source + ": " + std::to_string(n) +
                " samples; diagnose needs at least 4096 (two halves of 2048) for its "
                "held-out comparison and spectrum");
  if (!(data.rate_hz > 0)) throw Error(data.source + ": sampling rate must be > 0");
  for (const auto& c : data.channels) {
    if (c.x.size() != n) throw Error(data.source + ": channel " + c.name + " has a different length");
    for (std::size_t k = 0; k < c.x.size(); ++k)
      if (!std::isfinite(c.x[k]))
        throw Error(data.source + ": channel " + c.name + ": sample " + std::to_string(k) +
                    " is not finite");
  }
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
  return d;
}

}  // namespace navimpact::analysis
