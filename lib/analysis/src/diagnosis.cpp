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
#include <thread>
#include <tuple>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>

#include "diagnosis_internal.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/golden_section.hpp"
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

using stochastic::Model;
using stochastic::Process;
using stochastic::ProcessKind;

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

double wvDeviance(const std::vector<double>& nu_hat, const std::vector<double>& nu,
                  const std::vector<double>& eta) {
  // Gamma deviance: nu_hat ~ nu chi2_eta / eta  =>  -2 log-likelihood ratio
  // against the saturated fit = sum eta (r - log r - 1), r = nu_hat / nu.
  double d = 0;
  for (std::size_t j = 0; j < nu_hat.size(); ++j) {
    const double m = std::max(nu[j], 1e-300);
    const double r = nu_hat[j] / m;
    if (!(r > 0)) continue;
    d += eta[j] * (r - std::log(r) - 1.0);
  }
  return d;
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Cause causeOf(ProcessKind k) {
  switch (k) {
    case ProcessKind::WN: return Cause::WhiteNoise;
    case ProcessKind::QN: return Cause::QuantizationNoise;
    case ProcessKind::RW: return Cause::RandomWalk;
    case ProcessKind::DR: return Cause::Drift;
    case ProcessKind::GM: return Cause::GaussMarkov;
    case ProcessKind::SIN: return Cause::Sinusoid;
  }
  return Cause::WhiteNoise;
}

/// The parameter of a process whose square scales its WV.
/// The parameter of a process whose square scales its WV: the first
/// parameter of its kind in the registry (WN sigma, QN Q, RW gamma, DR omega,
/// GM sigma, SIN amp).
double& mainParam(Process& p) { return p.*(stochastic::kindInfo(p.kind).params.front().field); }

/// A process of kind @p k with unit scale and, where the kind has a second
/// (shape) parameter, that parameter set to @p shape (GM T [s], SIN freq [Hz]).
Process unitProcess(ProcessKind k, double shape = 1.0) {
  Process p;
  p.kind = k;
  const auto& params = stochastic::kindInfo(k).params;
  for (std::size_t i = 0; i < params.size(); ++i) p.*(params[i].field) = i == 0 ? 1.0 : shape;
  return p;
}

std::vector<double> wvOf(const Process& p, double rate, const std::vector<double>& tau) {
  std::vector<double> v(tau.size());
  for (std::size_t j = 0; j < tau.size(); ++j) v[j] = stochastic::haarWv(p, rate, tau[j]);
  return v;
}

std::vector<double> wvOf(const Model& m, const std::vector<double>& tau) {
  std::vector<double> v(tau.size(), 0.0);
  for (const auto& p : m.terms) {
    const auto w = wvOf(p, m.rate_hz, tau);
    for (std::size_t j = 0; j < tau.size(); ++j) v[j] += w[j];
  }
  return v;
}

std::vector<double> toStd(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

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

// --------------------------------------------------------------------------
// Candidate extensions: the WV of the current model plus (or with one term
// replaced by) one process family, its variance-like parameter a (sigma^2,
// Q^2, gamma^2, omega^2, GM sigma^2) and, for GM, T fitted by minimising the
// gamma deviance. Everything else in the model is kept as it is.

struct Candidate {
  bool retune = false;       ///< replace term `term` instead of adding
  int term = -1;
  ProcessKind kind = ProcessKind::WN;
  Process proc;              ///< fitted process (added or replacing)
  double deviance = kNaN;
  int params = 1;
  double T_lo = kNaN, T_hi = kNaN;  ///< GM: profile interval of T
  bool T_hi_open = false;            ///< GM: interval reaches the top of the T grid
  double scale = 1;          ///< retune: new / old variance parameter
  double p_lo = kNaN, p_hi = kNaN;   ///< 95 % profile interval of the main parameter
};

struct WvData {
  std::vector<double> tau;   ///< samples
  std::vector<double> nu;    ///< measured
  std::vector<double> dof;
  double samples = 0;        ///< record length [samples] (0: from the scales)
};

/// min over a >= 0 of deviance(base + a * shape) by a log grid and golden section.
double bestScale(const WvData& d, const std::vector<double>& base, const std::vector<double>& shape,
                 double* a_out) {
  const std::size_t J = d.nu.size();
  double amin = std::numeric_limits<double>::infinity(), amax = 0;
  for (std::size_t j = 0; j < J; ++j) {
    if (shape[j] > 0 && d.nu[j] > 0) {
      const double a = d.nu[j] / shape[j];
      amin = std::min(amin, a);
      amax = std::max(amax, a);
    }
  }
  std::vector<double> nu(J);
  auto dev = [&](double la) {
    const double a = std::exp(la);
    for (std::size_t j = 0; j < J; ++j) nu[j] = base[j] + a * shape[j];
    return wvDeviance(d.nu, nu, d.dof);
  };
  if (!(amax > 0)) {
    *a_out = 0;
    return wvDeviance(d.nu, base, d.dof);
  }
  const double l0 = std::log(amin) - 12.0, l1 = std::log(amax) + 1.0;
  const int G = 64;
  int gi = 0;
  double gbest = std::numeric_limits<double>::infinity();
  std::vector<double> gv(G + 1);
  for (int i = 0; i <= G; ++i) {
    gv[i] = dev(l0 + (l1 - l0) * i / G);
    if (gv[i] < gbest) {
      gbest = gv[i];
      gi = i;
    }
  }
  double a = l0 + (l1 - l0) * std::max(0, gi - 1) / G;
  double b = l0 + (l1 - l0) * std::min(G, gi + 1) / G;
  std::tie(a, b) = goldenSectionBracket(dev, a, b, 40);
  double la = 0.5 * (a + b), best = dev(la);
  if (gbest < best) {
    la = l0 + (l1 - l0) * gi / G;
    best = gbest;
  }
  // Zero contribution is allowed too (a = 0: the base alone).
  const double d0 = wvDeviance(d.nu, base, d.dof);
  if (d0 <= best) {
    *a_out = 0;
    return d0;
  }
  *a_out = std::exp(la);
  return best;
}

/// 95 % profile interval of a (deviance within chi2_1(0.95) = 3.84 of its
/// minimum at a_hat), by bisection in log a on each side.
std::pair<double, double> scaleInterval(const WvData& d, const std::vector<double>& base,
                                        const std::vector<double>& shape, double a_hat) {
  if (!(a_hat > 0)) return {0.0, 0.0};
  std::vector<double> nu(d.nu.size());
  auto dev = [&](double a) {
    for (std::size_t j = 0; j < nu.size(); ++j) nu[j] = base[j] + a * shape[j];
    return wvDeviance(d.nu, nu, d.dof);
  };
  const double target = dev(a_hat) + 3.84;
  auto side = [&](double factor) {
    double in = std::log(a_hat), out = in;
    for (int i = 0; i < 60; ++i) {  // expand until outside
      out += std::log(factor);
      if (dev(std::exp(out)) > target) break;
      if (i == 59) return std::exp(out);
    }
    for (int i = 0; i < 50; ++i) {
      const double mid = 0.5 * (in + out);
      (dev(std::exp(mid)) > target ? out : in) = mid;
    }
    return std::exp(in);
  };
  return {side(0.5), side(2.0)};
}

Candidate fitCandidate(bool retune, int term, ProcessKind kind, const Model& model,
                       const WvData& d) {
  Candidate c;
  c.retune = retune;
  c.term = term;
  c.kind = kind;
  const double rate = model.rate_hz;
  std::vector<double> base(d.tau.size(), 0.0);
  for (std::size_t i = 0; i < model.terms.size(); ++i) {
    if (retune && static_cast<int>(i) == term) continue;
    const auto w = wvOf(model.terms[i], rate, d.tau);
    for (std::size_t j = 0; j < base.size(); ++j) base[j] += w[j];
  }
  if (kind != ProcessKind::GM) {
    Process u = unitProcess(kind);
    const auto shape = wvOf(u, rate, d.tau);
    double a = 0;
    c.deviance = bestScale(d, base, shape, &a);
    c.proc = u;
    mainParam(c.proc) = std::sqrt(a);
    c.params = 1;
    const auto iv = scaleInterval(d, base, shape, a);
    c.p_lo = std::sqrt(iv.first);
    c.p_hi = std::sqrt(iv.second);
  } else {
    // GM: profile over T on a log grid from one sample to a fifth of the
    // record (a longer T is a random walk or a drift over this record).
    const double n_rec = d.samples > 0 ? d.samples : (d.tau.empty() ? 1 : 2 * d.tau.back());
    const double t0 = 1.0 / rate, t1 = 0.2 * n_rec / rate;
    const int G = 120;
    std::vector<double> Ts(G + 1), devs(G + 1), as(G + 1);
    int gi = 0;
    for (int i = 0; i <= G; ++i) {
      Ts[i] = t0 * std::pow(t1 / t0, static_cast<double>(i) / G);
      const auto shape = wvOf(unitProcess(ProcessKind::GM, Ts[i]), rate, d.tau);
      devs[i] = bestScale(d, base, shape, &as[i]);
      if (devs[i] < devs[gi]) gi = i;
    }
    // Golden refinement of log T between the grid neighbours.
    double a = std::log(Ts[std::max(0, gi - 1)]), b = std::log(Ts[std::min(G, gi + 1)]);
    auto prof = [&](double lT, double* aa) {
      const auto shape = wvOf(unitProcess(ProcessKind::GM, std::exp(lT)), rate, d.tau);
      return bestScale(d, base, shape, aa);
    };
    const double r = 0.5 * (std::sqrt(5.0) - 1.0);
    double aa = 0;
    double x1 = b - r * (b - a), x2 = a + r * (b - a);
    double f1 = prof(x1, &aa), f2 = prof(x2, &aa);
    for (int it = 0; it < 30; ++it) {
      if (f1 < f2) {
        b = x2; x2 = x1; f2 = f1; x1 = b - r * (b - a); f1 = prof(x1, &aa);
      } else {
        a = x1; x1 = x2; f1 = f2; x2 = a + r * (b - a); f2 = prof(x2, &aa);
      }
    }
    double lT = 0.5 * (a + b);
    double best = prof(lT, &aa);
    if (devs[gi] < best) {
      lT = std::log(Ts[gi]);
      best = devs[gi];
      aa = as[gi];
    }
    c.deviance = best;
    c.proc = Process::gm(std::sqrt(std::max(aa, 0.0)), std::exp(lT));
    c.params = 2;
    // 95 % profile interval of T: deviance within chi2_1(0.95) = 3.84 of the minimum.
    double lo = std::exp(lT), hi = std::exp(lT);
    for (int i = 0; i <= G; ++i)
      if (devs[i] <= best + 3.84) {
        lo = std::min(lo, Ts[i]);
        hi = std::max(hi, Ts[i]);
      }
    // The grid resolves T to one grid step at best: never narrower than that.
    c.T_lo = std::min(lo, Ts[std::max(0, gi - 1)]);
    c.T_hi = std::max(hi, Ts[std::min(G, gi + 1)]);
    // A GM whose T the data do not bound below a fifth of the record (best
    // T at the top of the grid, or its 95 % profile interval reaching it) is
    // a random walk or a drift over this record; one at the bottom (one
    // sample) is white noise. Either is left to those candidates.
    c.T_hi_open = gi >= G - 1 || lT >= std::log(Ts[G - 1]) || devs[G] <= best + 3.84 ||
                  // T at the bottom of the grid (one sample): white noise, not a GM
                  gi <= 1 || lT <= std::log(Ts[1]);
    c.p_lo = c.p_hi = kNaN;
  }
  if (retune) {
    const Process& old = model.terms[term];
    Process o = old;
    const double olda = mainParam(o);
    c.scale = olda > 0 ? mainParam(c.proc) * mainParam(c.proc) / (olda * olda) : kNaN;
  }
  return c;
}

/// Apply a candidate to a model: add (merging WN/QN/RW/DR into an existing
/// term of the same kind, their variances add) or replace the tuned term.
Model applyCandidate(const Model& m, const Candidate& c) {
  Model out = m;
  if (c.retune) {
    out.terms[c.term] = c.proc;
    return out;
  }
  if (c.kind != ProcessKind::GM) {
    for (auto& t : out.terms) {
      if (t.kind == c.kind) {
        double& a = mainParam(t);
        Process p = c.proc;
        a = std::sqrt(a * a + mainParam(p) * mainParam(p));
        return out;
      }
    }
  }
  if (mainParam(const_cast<Process&>(c.proc)) > 0) out.terms.push_back(c.proc);
  return out;
}

std::vector<Candidate> allCandidates(const Model& m, const WvData& d) {
  std::vector<Candidate> cands;
  for (ProcessKind k : {ProcessKind::WN, ProcessKind::QN, ProcessKind::RW, ProcessKind::DR,
                        ProcessKind::GM})
    cands.push_back(fitCandidate(false, -1, k, m, d));
  for (std::size_t i = 0; i < m.terms.size(); ++i) {
    if (m.terms[i].kind == ProcessKind::SIN) continue;
    cands.push_back(fitCandidate(true, static_cast<int>(i), m.terms[i].kind, m, d));
  }
  return cands;
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

struct Budget {
  double wv, spec, steps, spikes;  ///< family-wise level of each test family, per channel
};

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

std::string candidateText(const Candidate& c) {
  Process p = c.proc;
  std::string s = c.retune ? "retuned " : "";
  s += stochastic::formatTerms({p}, 3);
  return s;
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
  if (count > 0)
    ex << "the measured WV is " << formatNumber(above ? ratio : 1.0 / ratio, 2) << "x "
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

/// GMWM refit of @p start's structure (SIN terms kept as they are) on @p wv,
/// warm-started at @p start; returns the refit when its gamma deviance on @p d
/// is not above the start's, else @p start. @p how says which was kept.
Model gmwmRefit(const Model& start, const gmwm::WaveletVariance& wv, const WvData& d,
                std::string* how) {
  Model core = start, sins = start;
  core.terms.clear();
  sins.terms.clear();
  for (const auto& p : start.terms) (p.kind == ProcessKind::SIN ? sins : core).terms.push_back(p);
  std::vector<ProcessKind> structure;
  for (const auto& p : core.terms) structure.push_back(p.kind);
  if (structure.empty() || gmwm::parameterCount(structure) > wv.scales()) {
    *how = "none (structure too large for the scales)";
    return start;
  }
  Model refit;
  try {
    gmwm::FitOptions fo;
    fo.warm_starts = {core};
    fo.max_starts = 2;
    refit = gmwm::fit(structure, wv, fo).model;
  } catch (const Error& e) {
    *how = std::string("start kept (GMWM refit failed: ") + e.what() + ")";
    return start;
  }
  refit.rate_hz = start.rate_hz;
  // "Keeping the parts that were right": a refit that collapses a term of the
  // start (its variance-like parameter below 1e-3 of the start's) or moves a GM
  // below one sample of correlation time (practically white, what GMWM does on
  // quantised data) trades a term for another rather than refining it.
  {
    auto params = [](const Model& m, ProcessKind k) {
      std::vector<double> v;
      for (Process p : m.terms)
        if (p.kind == k) v.push_back(mainParam(p));
      std::sort(v.rbegin(), v.rend());
      return v;
    };
    auto subSample = [&](const Model& m) {
      int c = 0;
      for (const auto& p : m.terms) c += (p.kind == ProcessKind::GM && p.T < 1.0 / start.rate_hz) ? 1 : 0;
      return c;
    };
    for (ProcessKind k : {ProcessKind::WN, ProcessKind::QN, ProcessKind::RW, ProcessKind::DR,
                          ProcessKind::GM}) {
      const auto pa = params(core, k), pb = params(refit, k);
      for (std::size_t i = 0; i < pa.size() && i < pb.size(); ++i)
        if (pa[i] > 0 && pb[i] < 1e-3 * pa[i]) {
          *how = "start kept (the GMWM refit " + stochastic::formatTerms(refit.terms, 3) +
                 " collapsed a term of " + stochastic::formatTerms(core.terms, 3) + ")";
          return start;
        }
    }
    if (subSample(refit) > subSample(core)) {
      *how = "start kept (the GMWM refit " + stochastic::formatTerms(refit.terms, 3) +
             " has a GM below one sample of correlation time)";
      return start;
    }
  }
  for (const auto& p : sins.terms) refit.terms.push_back(p);
  const double dev0 = wvDeviance(d.nu, wvOf(core, d.tau), d.dof);
  Model rc = refit;
  rc.terms.erase(std::remove_if(rc.terms.begin(), rc.terms.end(),
                                [](const Process& p) { return p.kind == ProcessKind::SIN; }),
                 rc.terms.end());
  const double dev1 = wvDeviance(d.nu, wvOf(rc, d.tau), d.dof);
  if (dev1 <= dev0 + 1e-9 * std::abs(dev0)) {
    *how = "gmwm (deviance " + formatNumber(dev0, 4) + " -> " + formatNumber(dev1, 4) + ")";
    return refit;
  }
  *how = "start kept (GMWM refit raised the deviance " + formatNumber(dev0, 4) + " -> " + formatNumber(dev1, 4) + ")";
  return start;
}

/// Best stochastic extension of @p m on the WV @p d: up to @p max_terms
/// greedy additions or retunings by AIC (as the cause search), used as the
/// alternative explanation of candidate level shifts. *params: parameters added.
Model greedyExtension(const Model& m, const WvData& d, int max_terms, int* params) {
  Model cur = m;
  *params = 0;
  double cur_dev = wvDeviance(d.nu, wvOf(cur, d.tau), d.dof);
  for (int it = 0; it < max_terms; ++it) {
    const auto cands = allCandidates(cur, d);
    int best = -1;
    double best_crit = cur_dev;
    for (std::size_t i = 0; i < cands.size(); ++i) {
      Process pp = cands[i].proc;
      if (!(mainParam(pp) > 0)) continue;
      if (cands[i].kind == ProcessKind::GM && cands[i].T_hi_open) continue;
      const double crit = cands[i].deviance + 2.0 * cands[i].params + (cands[i].retune ? 4.0 : 0.0);
      if (crit < best_crit) {
        best_crit = crit;
        best = static_cast<int>(i);
      }
    }
    if (best < 0) break;
    cur = applyCandidate(cur, cands[best]);
    *params += cands[best].params;
    cur_dev = cands[best].deviance;
  }
  return cur;
}

/// Model without its SIN terms (the null of the detectors; lines are excluded by frequency).
Model withoutSin(const Model& m) {
  Model o = m;
  o.terms.erase(std::remove_if(o.terms.begin(), o.terms.end(),
                               [](const Process& p) { return p.kind == ProcessKind::SIN; }),
                o.terms.end());
  return o;
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
  const double record_s = static_cast<double>(n) / rate;
  const double t0 = sh.data->t0_s;
  ChannelDiagnosis cd;
  cd.name = chan.name;
  cd.model_before = sh.model->forChannel(chan.name);
  const Model& m0 = cd.model_before;
  const Model m0n = withoutSin(m0);
  std::vector<double> model_sin_hz;
  for (const auto& p : m0.terms)
    if (p.kind == ProcessKind::SIN) model_sin_hz.push_back(p.freq_hz);
  const Budget& B = sh.per_channel;
  const std::string unit = channelUnit(cd.name);

  std::vector<double> x = chan.x;
  double mean = 0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  for (double& v : x) v -= mean;
  const std::vector<double> raw = x;

  // 1. Outlier events (spikes, bursts such as a knock), interpolated out.
  {
    const auto orr = detect::detectOutliers(x, detect::secondDifferenceSd(m0n), B.spikes);
    detect::cleanOutliers(x, orr.events);
    if (!orr.events.empty()) {
      Finding f;
      f.channel = cd.name;
      f.cause = Cause::Outliers;
      double maxz = 0, maxa = 0, longest = 0;
      int samples = 0;
      for (const auto& e : orr.events) {
        f.times_s.push_back(t0 + static_cast<double>(e.peak) / rate);
        maxz = std::max(maxz, e.peak_z);
        maxa = std::max(maxa, std::abs(e.peak_value));
        longest = std::max(longest, static_cast<double>(e.last - e.first + 1) / rate);
        samples += e.exceedances;
        cd.outlier_events.push_back({t0 + static_cast<double>(e.first) / rate,
                                     static_cast<double>(e.last - e.first + 1) / rate, e.peak_value});
      }
      f.params = {{"count", static_cast<double>(orr.events.size())}};
      f.range_key = "t_s";
      f.range_lo = f.times_s.front();
      f.range_hi = f.times_s.back();
      f.statistic = maxz;
      f.threshold = orr.threshold;
      f.p_value = std::min(1.0, 2.0 * static_cast<double>(n) *
                                    boost::math::cdf(boost::math::complement(boost::math::normal(), maxz)));
      const bool heavy = orr.events.size() > std::max<std::size_t>(20, n / 5000);
      std::ostringstream ex;
      ex << orr.events.size() << " outlier event(s)" << (longest > 1.5 / rate ? " (bursts up to " + formatNumber(longest, 2) + " s count once)" : "")
         << ", up to " << formatNumber(maxa, 3) << " " << unit << " from the local level, " << formatNumber(maxz, 3)
         << " sd of the second difference (threshold " << formatNumber(orr.threshold, 3) << ").";
      f.explanation = ex.str();
      f.evidence = heavy ? "so many events throughout the record point to heavy-tailed noise rather than isolated outliers"
                         : "Gaussian noise of the model exceeds this threshold anywhere in the record with probability below the outlier share of alpha; a step would leave the level changed, these return to it";
      f.action = heavy ? "estimate the model robustly (`navimpact wv --robust`); heavy-tailed noise is not a filter state"
                       : "remove them before estimating (they were interpolated here); not a filter state";
      cd.findings.push_back(f);
    }
  }
  sh.tick(cd.name + ": outliers");

  // 2. Spectral lines against the model's PSD, subtracted.
  std::vector<detect::SpectralLine> lines;
  {
    detect::LineTestOptions lo;
    lo.exclude_hz = model_sin_hz;
    const auto lt = detect::detectLines(x, rate, detect::psdOf(m0n), B.spec, lo);
    lines = lt.lines;
    cd.spectrum.freq_hz = lt.plot_freq_hz;
    cd.spectrum.psd = lt.plot_psd;
    cd.spectrum.background = lt.plot_background;
    cd.spectrum.threshold_ratio = lt.threshold;
    cd.spectrum.bins_tested = lt.bins_tested;
    cd.spectrum.bin_hz = lt.bin_hz;
    cd.spectrum.f_min_hz = lt.f_min_hz;
    cd.spectrum.f_max_hz = lt.f_max_hz;
    // A line within 10 bins of a stronger one is the same line wandering in
    // frequency (what a real vibration does): one finding, both subtracted.
    std::vector<int> near_of(lines.size(), -1);
    for (std::size_t i = 0; i < lines.size(); ++i) {
      if (lines[i].harmonic_of >= 0) continue;
      for (std::size_t j = 0; j < i; ++j)
        if (lines[j].harmonic_of < 0 && near_of[j] < 0 &&
            std::abs(lines[i].freq_hz - lines[j].freq_hz) <= 10.0 * lt.bin_hz) {
          near_of[i] = static_cast<int>(j);
          break;
        }
    }
    for (std::size_t i = 0; i < lines.size(); ++i) {
      const auto& L = lines[i];
      cd.line_freqs_hz.push_back(L.freq_hz);
      if (L.harmonic_of >= 0 || near_of[i] >= 0) continue;
      Finding f;
      f.channel = cd.name;
      f.cause = Cause::Sinusoid;
      f.params = {{"amplitude", L.amplitude}, {"freq_hz", L.freq_hz}};
      const double fse = std::max(L.freq_se_hz, 0.0);
      f.intervals.push_back({"freq_hz", {L.freq_hz - 1.96 * fse, L.freq_hz + 1.96 * fse}});
      f.intervals.push_back({"amplitude", {std::max(0.0, L.amplitude - 1.96 * L.amp_se), L.amplitude + 1.96 * L.amp_se}});
      for (const auto& H : lines)
        if (H.harmonic_of == static_cast<int>(i)) f.harmonics_hz.push_back(H.freq_hz);
      std::sort(f.harmonics_hz.begin(), f.harmonics_hz.end());
      f.range_key = "freq_hz";
      f.range_lo = L.freq_hz - lt.bin_hz;
      f.range_hi = L.freq_hz + lt.bin_hz;
      f.statistic = L.ratio;
      f.threshold = lt.threshold;
      f.p_value = L.p_value;
      std::ostringstream ex;
      ex << "a spectral line at " << formatNumber(L.freq_hz, 6) << " Hz, amplitude " << formatNumber(L.amplitude, 3) << " " << unit
         << " (" << formatNumber(L.ratio, 3) << "x the background; threshold " << formatNumber(lt.threshold, 3) << "x)";
      if (!f.harmonics_hz.empty()) {
        ex << ", with harmonic(s) at";
        for (double h : f.harmonics_hz) ex << " " << formatNumber(h, 5);
        ex << " Hz";
      }
      {
        std::string nearby;
        for (std::size_t q = 0; q < lines.size(); ++q)
          if (near_of[q] == static_cast<int>(i)) nearby += " " + formatNumber(lines[q].freq_hz, 6);
        if (!nearby.empty()) ex << "; its frequency wanders (also at" << nearby << " Hz)";
      }
      ex << ".";
      f.explanation = ex.str();
      std::ostringstream ev;
      ev << "peak " << formatNumber(L.local_ratio, 3) << "x its own spectral neighbourhood: a Gauss-Markov process has a smooth spectrum and cannot make it; amplitude "
         << formatNumber(L.amp_half[0], 3) << " / " << formatNumber(L.amp_half[1], 3) << " " << unit << " in the two halves";
      f.evidence = ev.str();
      f.action = "add SIN(amp, freq) per line (a two-state oscillator in the filter), or notch it out if it is a vibration of the test set-up";
      cd.findings.push_back(f);
    }
  }
  sh.tick(cd.name + ": spectrum");

  // 3. Level shifts, detected under the model and accepted only when each is
  // significant against the best stochastic explanation of the record
  // without shifts (a random walk, a long Gauss-Markov or a drift also make
  // large window contrasts): exact likelihood-ratio test of block means,
  // Bonferroni over the block boundaries (detect/step_test.hpp).
  const auto wv_pre = gmwm::waveletVariance(x.data(), n, rate);
  const std::vector<double> tau = toStd(wv_pre.tau);
  const std::size_t findings_pre = cd.findings.size();
  bool x_after_pre_changed = false;
  {
    std::vector<double> xs = x;
    auto cpr = detect::detectChangePoints(xs, detect::haarWvOf(m0n), B.steps);
    // The best stochastic explanation of the record without shifts (the
    // runner-up of every shift and transient).
    int p_ext0 = 0;
    const Model ext0_model = [&]() {
      if (cpr.transients.empty() && cpr.changes.empty()) return m0n;  // only needed to judge those
      WvData d0{tau, toStd(wv_pre.wv), toStd(wv_pre.eta), static_cast<double>(n)};
      return greedyExtension(m0n, d0, opt.max_terms, &p_ext0);
    }();
    // Transients (a knock, a bump): at most 1 s long, seen in windows of at
    // most 1 s, and still beyond the threshold under that stochastic
    // explanation; others are left alone.
    {
      const auto wv_ext0 = detect::haarWvOf(ext0_model);
      cpr.transients.erase(
          std::remove_if(cpr.transients.begin(), cpr.transients.end(),
                         [&](const detect::Transient& tr) {
                           const double dur = static_cast<double>(tr.last - tr.first) / rate;
                           const double sd = 2.0 * std::sqrt(wv_ext0(2.0 * static_cast<double>(tr.half_width)));
                           const double win = static_cast<double>(tr.half_width) / rate;
                           return dur > 1.0 || win > 1.0 || !(std::abs(tr.peak) >= tr.threshold * sd);
                         }),
          cpr.transients.end());
    }
    if (!cpr.transients.empty()) {
      // Transients: outlier events, interpolated out.
      std::vector<detect::OutlierEvent> evs;
      for (const auto& tr : cpr.transients) {
        detect::OutlierEvent e;
        e.first = tr.first;
        e.last = tr.last > tr.first ? tr.last - 1 : tr.first;
        e.peak = tr.first;
        e.peak_value = tr.peak;
        e.peak_z = tr.z;
        evs.push_back(e);
        cd.outlier_events.push_back({t0 + static_cast<double>(tr.first) / rate,
                                     static_cast<double>(tr.last - tr.first) / rate, tr.peak});
      }
      detect::cleanOutliers(x, evs);
      x_after_pre_changed = true;
      Finding* of = nullptr;
      for (auto& f : cd.findings)
        if (f.cause == Cause::Outliers) of = &f;
      if (!of) {
        Finding f;
        f.channel = cd.name;
        f.cause = Cause::Outliers;
        f.params = {{"count", 0.0}};
        f.range_key = "t_s";
        f.statistic = cpr.transients.front().z;
        f.threshold = cpr.transients.front().threshold;
        f.p_value = cpr.transients.front().p_value;
        f.evidence = "level changes that undo each other within their detection window: a transient, not a level shift";
        f.action = "remove them before estimating (they were interpolated here); not a filter state";
        cd.findings.push_back(f);
        of = &cd.findings.back();
      }
      for (const auto& tr : cpr.transients) of->times_s.push_back(t0 + static_cast<double>(tr.first) / rate);
      std::sort(of->times_s.begin(), of->times_s.end());
      of->params = {{"count", static_cast<double>(of->times_s.size())}};
      of->range_lo = of->times_s.front();
      of->range_hi = of->times_s.back();
      of->explanation = std::to_string(of->times_s.size()) +
                        " outlier event(s): spikes, bursts or transients (a knock) that return to the local level; "
                        "each counts once however many samples it spans.";
    }
    if (!cpr.changes.empty()) {
      // Shift or wandering: exact likelihood ratio of each candidate shift
      // (forward selection, each given those accepted before it) under the
      // best stochastic explanation of the record without shifts, ext0; chi2_1
      // at a fixed time, Bonferroni over the block boundaries a detector can
      // pick (detect/step_test.hpp): the level holds whatever wanders.
      std::vector<std::size_t> idx;
      for (const auto& c : cpr.changes) idx.push_back(c.index);
      const int K = static_cast<int>(cpr.changes.size());
      const std::string ext0 =
          p_ext0 > 0 ? stochastic::formatTerms(ext0_model.terms, 3) : std::string("the model as given");
      detect::StepTestResult st;
      std::string failed;
      try {
        st = detect::testLevelShifts(x, ext0_model, idx, B.steps);
      } catch (const Error& e) {
        failed = e.what();
      }
      const int best_k = static_cast<int>(st.accepted());
      const double boundaries = static_cast<double>(st.blocks > 1 ? st.blocks - 1 : 1);
      const double lr_thr =
          boost::math::quantile(boost::math::complement(boost::math::chi_squared(1.0), B.steps / boundaries));
      const std::string how = "generalised likelihood ratio, every variance profiled and a random walk allowed; exact Gaussian likelihood of " +
                              std::to_string(st.blocks) + " block means of " + std::to_string(st.block) +
                              " sample(s); chi2_1 at a fixed time, Bonferroni over the " +
                              formatNumber(boundaries, 6) + " block boundaries: threshold " + formatNumber(lr_thr, 4);
      if (best_k > 0) {
        x_after_pre_changed = true;
        double lr_rest = 0;  // strongest candidate left out
        for (std::size_t q = 0; q < st.tests.size(); ++q) {
          const auto& c = cpr.changes[q];
          const auto& t = st.tests[q];
          if (!t.accepted) {
            lr_rest = std::max(lr_rest, t.lr);
            continue;
          }
          const double size = t.size, se = t.size_se;
          for (std::size_t k = c.index; k < n; ++k) x[k] -= size;
          Finding f;
          f.channel = cd.name;
          f.cause = Cause::LevelShift;
          const double tt = t0 + static_cast<double>(c.index) / rate;
          f.params = {{"size", size}, {"t_s", tt}};
          f.intervals.push_back({"size", {size - 1.96 * se, size + 1.96 * se}});
          f.range_key = "t_s";
          f.range_lo = f.range_hi = tt;
          f.statistic = t.lr;
          f.threshold = lr_thr;
          f.p_value = t.p_value;
          f.explanation = "a level shift of " + formatNumber(size, 3) + " " + unit + " at t = " + formatNumber(tt, 6) +
                          " s (" + formatNumber(std::abs(size) / std::max(se, 1e-300), 3) + " standard errors; found by the model's " +
                          formatNumber(c.half_width / rate, 3) + " s window contrast at " + formatNumber(c.z, 3) + " sd).";
          f.evidence = "likelihood ratio " + formatNumber(t.lr, 4) + " for a shift here against the best stochastic explanation without shifts, " +
                       ext0 + " (" + how + "; p = " + formatNumber(t.p_value, 3) + ")";
          f.action = "segment the record at t = " + formatNumber(tt, 6) +
                     " s (estimate the model on each part) or remove the step; a stationary filter state cannot represent a one-off jump";
          cd.findings.push_back(f);
        }
        if (best_k < K)
          cd.notes.push_back(std::to_string(K - best_k) + " weaker candidate level shift(s) are not significant given the " +
                             std::to_string(best_k) + " found (likelihood ratio up to " + formatNumber(lr_rest, 4) +
                             " below " + formatNumber(lr_thr, 4) + "): left to the wavelet-variance analysis");
      } else if (!failed.empty()) {
        cd.notes.push_back(std::to_string(K) + " candidate level shift(s) not tested (" + failed +
                           "): left to the wavelet-variance analysis");
      } else {
        cd.notes.push_back(std::to_string(K) + " candidate level shift(s) are explained as well by " + ext0 +
                           " (likelihood ratio up to " + formatNumber([&] {
                             double v = 0;
                             for (const auto& t : st.tests) v = std::max(v, t.lr);
                             return v;
                           }(), 4) + ", " + how +
                           "): left to the wavelet-variance analysis");
      }
    }
  }
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
  std::map<int, std::size_t> added_by;  ///< term index added here -> its finding
  // Block means of the cleaned record for the exact likelihood that decides
  // between the slow explanations (random walk, drift, long Gauss-Markov),
  // which differ only at the coarsest WV scales where it has few dof.
  const std::size_t blk = std::max<std::size_t>(1, n / 512);
  const std::vector<double> yb = stochastic::blockMeans(x.data(), n, blk);
  auto isSlow = [&](const Candidate& c) {
    if (c.kind == ProcessKind::RW || c.kind == ProcessKind::DR) return true;
    return c.kind == ProcessKind::GM && !c.retune && c.proc.T * rate >= 4.0 * static_cast<double>(blk);
  };
  auto chk = chk_cl;
  for (int it = 0; it < opt.max_terms && countSignificant(chk) > 0; ++it) {
    // Cause chosen on the whole cleaned record (all scales: the coarsest
    // ones separate random walk, drift and long Gauss-Markov), by AIC.
    auto cands = allCandidates(m_full, full);
    int best = -1, second = -1;
    double best_crit = std::numeric_limits<double>::infinity(), second_crit = best_crit;
    std::vector<double> crits(cands.size(), std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < cands.size(); ++i) {
      Process pp = cands[i].proc;
      // No vanishing terms; a GM whose T reaches a fifth of the record is a
      // random walk or a drift over this record (left to those candidates).
      if (!(mainParam(pp) > 0)) continue;
      if (cands[i].kind == ProcessKind::GM && cands[i].T_hi_open) continue;
      // AIC; retuning a term of the user's model discards what they had, so it
      // is charged as if it cost two more parameters.
      crits[i] = cands[i].deviance + 2.0 * cands[i].params + (cands[i].retune ? 4.0 : 0.0);
    }
    for (std::size_t i = 0; i < cands.size(); ++i) {
      if (crits[i] < best_crit - 1e-9) {
        second = best;
        second_crit = best_crit;
        best_crit = crits[i];
        best = static_cast<int>(i);
      } else if (crits[i] < second_crit - 1e-9) {
        second_crit = crits[i];
        second = static_cast<int>(i);
      }
    }
    if (best < 0) break;
    {
      const double cur = wvDeviance(full.nu, wvOf(m_full, full.tau), full.dof);
      if (!(best_crit < cur)) break;
    }
    // Slow explanations compared by the exact Gaussian likelihood of the block
    // means (every variance profiled, a drift's slope by GLS), AIC.
    std::string exact_evidence;
    if (isSlow(cands[best]) && yb.size() >= 16) {
      std::vector<std::pair<double, int>> ranked;
      for (std::size_t i = 0; i < cands.size(); ++i) {
        if (!std::isfinite(crits[i]) || !isSlow(cands[i])) continue;
        Model mc = withoutSin(applyCandidate(m_full, cands[i]));
        const bool trend = mc.count(ProcessKind::DR) > 0;
        Eigen::MatrixXd X(static_cast<Eigen::Index>(yb.size()), trend ? 2 : 1);
        for (std::size_t k = 0; k < yb.size(); ++k) {
          X(static_cast<Eigen::Index>(k), 0) = 1.0;
          if (trend) X(static_cast<Eigen::Index>(k), 1) = (static_cast<double>(k) + 0.5) / static_cast<double>(yb.size()) - 0.5;
        }
        // Only the candidate's own term is profiled (a drift's slope is the
        // GLS trend): each explanation gets one addition to the model.
        int own = -1;
        if (cands[i].retune) own = cands[i].term;
        else if (cands[i].kind == ProcessKind::GM) own = static_cast<int>(mc.terms.size()) - 1;
        else if (cands[i].kind == ProcessKind::RW)
          for (std::size_t q = 0; q < mc.terms.size(); ++q)
            if (mc.terms[q].kind == ProcessKind::RW) own = static_cast<int>(q);
        try {
          const double l = stochastic::profileBlockLogLikelihood(mc, yb, blk, X, {own});
          ranked.push_back({-2.0 * l + 2.0 * cands[i].params + (cands[i].retune ? 4.0 : 0.0), static_cast<int>(i)});
        } catch (const Error&) {
        }
      }
      std::sort(ranked.begin(), ranked.end());
      if (ranked.size() >= 2) {
        const int wv_best = best;
        best = ranked[0].second;
        best_crit = crits[best];
        second = ranked[1].second;
        second_crit = crits[second];
        exact_evidence = "; among the slow explanations the exact likelihood of " + std::to_string(yb.size()) +
                         " block means (variances profiled) gives AIC " + formatNumber(ranked[0].first, 7) + " against " +
                         formatNumber(ranked[1].first, 7) + " for " + candidateText(cands[second]) +
                         (best != wv_best ? " (the WV alone preferred " + candidateText(cands[wv_best]) + ")" : std::string());
      }
    }
    const Candidate& ch = cands[best];
    const Candidate cf = ch;
    // The same family fitted on the first half, for the held-out gain.
    const Candidate chh = (ch.retune && ch.term >= static_cast<int>(m_half.terms.size()))
                              ? ch
                              : fitCandidate(ch.retune, ch.term, ch.kind, m_half, h1);
    const Model before = m_full;
    const Model after = applyCandidate(m_full, cf);
    // A finding must change the WV by at least its CI width at some scale.
    if (wvChangeInCiWidths(chk, wvOf(before, tau), wvOf(after, tau)) < 1.0) break;
    Finding nf = broadbandFinding(cd.name, cf, before, chk, tau, rate);
    double pmin = 1;
    for (const auto& s : chk) pmin = std::min(pmin, s.p_value);
    nf.statistic = pmin;
    nf.threshold = p_thr;
    nf.p_value = std::min(1.0, pmin * J * sh.channels / 0.4);  // Bonferroni over scales and channels (WV share)
    nf.evidence = "AIC " + formatNumber(best_crit, 5) +
                  (second >= 0 ? " against " + formatNumber(second_crit, 5) + " for the runner-up, " + candidateText(cands[second])
                               : std::string(" (no other family fits)")) +
                  exact_evidence;
    auto own = added_by.find(cf.retune ? cf.term : -1);
    if (cf.retune && own != added_by.end()) {
      Finding& old = cd.findings[own->second];
      old.params = nf.params;
      old.T_interval_s = nf.T_interval_s;
      old.intervals = nf.intervals;
    } else {
      cd.findings.push_back(nf);
      if (!cf.retune && !(cf.kind != ProcessKind::GM && m_full.count(cf.kind) > 0))
        added_by[static_cast<int>(m_full.terms.size())] = cd.findings.size() - 1;
    }
    m_full = after;
    {
      Process ph = chh.proc;
      if (mainParam(ph) > 0) m_half = applyCandidate(m_half, chh);
    }
    added_params += ch.params;
    chk = checkScales(wv_cl, wvOf(m_full, tau), dof, p_thr, {}, {});
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
  std::atomic<int> next{0};
  std::mutex err_mu;
  std::string first_error;
  int first_error_ch = -1;
  auto worker = [&]() {
    for (;;) {
      const int i = next++;
      if (i >= static_cast<int>(data.channels.size())) return;
      try {
        d.channels[i] = diagnoseChannel(sh, i);
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lk(err_mu);
        if (first_error_ch < 0 || i < first_error_ch) {
          first_error_ch = i;
          first_error = data.source + ": channel " + data.channels[i].name + ": " + e.what();
        }
      }
    }
  };
  int threads = opt.threads > 0 ? opt.threads
                                : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = std::min<int>(threads, static_cast<int>(data.channels.size()));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (first_error_ch >= 0) throw Error(first_error);
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
