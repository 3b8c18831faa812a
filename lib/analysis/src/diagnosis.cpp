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

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>

#include "diagnosis_internal.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/gmwm/wavelet_variance.hpp"
#include "navimpact/gmwm/estimator.hpp"
#include "navimpact/stochastic/model_text.hpp"
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

std::string fmtNum(double v, int digits) {
  std::ostringstream os;
  os.precision(digits);
  os << v;
  return os.str();
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
double& mainParam(Process& p) {
  switch (p.kind) {
    case ProcessKind::WN: return p.sigma;
    case ProcessKind::QN: return p.Q;
    case ProcessKind::RW: return p.gamma;
    case ProcessKind::DR: return p.omega;
    case ProcessKind::GM: return p.sigma;
    case ProcessKind::SIN: return p.amp;
  }
  return p.sigma;
}

Process unitProcess(ProcessKind k, double T = 1.0) {
  switch (k) {
    case ProcessKind::WN: return Process::wn(1.0);
    case ProcessKind::QN: return Process::qn(1.0);
    case ProcessKind::RW: return Process::rw(1.0);
    case ProcessKind::DR: return Process::dr(1.0);
    case ProcessKind::GM: return Process::gm(1.0, T);
    case ProcessKind::SIN: return Process::sin(1.0, 1.0);
  }
  return Process::wn(1.0);
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
};

struct WvData {
  std::vector<double> tau;   ///< samples
  std::vector<double> nu;    ///< measured
  std::vector<double> dof;
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
  const double r = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = b - r * (b - a), e = a + r * (b - a);
  double fc = dev(c), fe = dev(e);
  for (int it = 0; it < 40; ++it) {
    if (fc < fe) {
      b = e;
      e = c;
      fe = fc;
      c = b - r * (b - a);
      fc = dev(c);
    } else {
      a = c;
      c = e;
      fc = fe;
      e = a + r * (b - a);
      fe = dev(e);
    }
  }
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
  } else {
    // GM: profile over T on a log grid from one sample to 10x the record.
    const double n_rec = d.tau.empty() ? 1 : 2 * d.tau.back();
    const double t0 = 1.0 / rate, t1 = 10.0 * n_rec / rate;
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
    c.T_lo = lo;
    c.T_hi = hi;
    c.T_hi_open = devs[G] <= best + 3.84;
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
  return fmtNum(lo, 3) + "–" + fmtNum(hi, 3) + " s";
}

/// Range of scales that a change of model explains: flagged (outside the
/// per-scale 95 % CI) scales whose log misfit the change reduces.
void explainedRange(const std::vector<ScaleCheck>& chk, const std::vector<double>& nu_before,
                    const std::vector<double>& nu_after, double* lo, double* hi,
                    double* max_ratio, double* max_widths) {
  *lo = kNaN;
  *hi = kNaN;
  *max_ratio = 1;
  *max_widths = 0;
  double best_gain = 0;
  std::size_t jbest = 0;
  for (std::size_t j = 0; j < chk.size(); ++j) {
    const double mb = std::abs(std::log(chk[j].measured / std::max(nu_before[j], 1e-300)));
    const double ma = std::abs(std::log(chk[j].measured / std::max(nu_after[j], 1e-300)));
    if (mb - ma > best_gain) {
      best_gain = mb - ma;
      jbest = j;
    }
    if (!chk[j].outside95 || !(mb - ma > 0.5 * mb)) continue;
    if (std::isnan(*lo)) *lo = chk[j].tau_s;
    *hi = chk[j].tau_s;
    const double r = chk[j].ratio;
    if (std::abs(std::log(r)) > std::abs(std::log(*max_ratio))) *max_ratio = r;
    if (std::abs(chk[j].ci_widths) > std::abs(*max_widths)) *max_widths = chk[j].ci_widths;
  }
  if (std::isnan(*lo) && !chk.empty()) {
    *lo = *hi = chk[jbest].tau_s;
    *max_ratio = chk[jbest].ratio;
    *max_widths = chk[jbest].ci_widths;
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
  double lo, hi, ratio, widths;
  explainedRange(chk, nb, na, &lo, &hi, &ratio, &widths);
  f.range_key = "scales_s";
  f.range_lo = lo;
  f.range_hi = hi;
  const std::string unit = channelUnit(ch);
  Process p = c.proc;
  std::ostringstream ex;
  const bool above = ratio >= 1;
  f.direction = (c.retune && c.scale < 1) ? "overstated" : "missing";
  ex << "measured WV " << (above ? "exceeds" : "is below") << " the model by "
     << fmtNum(above ? ratio : 1.0 / ratio, 2) << "x at tau = " << scaleRange(lo, hi)
     << ", outside the 95 % CI (by up to " << fmtNum(std::abs(widths), 2)
     << " CI widths, family-wise significant); ";
  switch (c.kind) {
    case ProcessKind::WN:
      f.params = {{"sigma", p.sigma}};
      break;
    case ProcessKind::QN:
      f.params = {{"Q", p.Q}};
      break;
    case ProcessKind::RW:
      f.params = {{"gamma", p.gamma}};
      break;
    case ProcessKind::DR:
      f.params = {{"omega", p.omega}};
      break;
    case ProcessKind::GM:
      f.params = {{"sigma", p.sigma}, {"T", p.T}};
      f.T_interval_s = std::make_pair(c.T_lo, c.T_hi);
      break;
    case ProcessKind::SIN:
      f.params = {{"amplitude", p.amp}, {"freq_hz", p.freq_hz}};
      break;
  }
  if (c.retune) {
    Process old = before.terms[c.term];
    ex << "the model's " << stochastic::formatTerms({old}, 3) << " is "
       << (c.scale < 1 ? "overstated" : "understated") << "; the WV fits "
       << stochastic::formatTerms({p}, 3);
  } else {
    ex << "the excess " << shapeWords(c.kind);
    if (c.kind == ProcessKind::GM)
      ex << " with T ≈ " << fmtNum(p.T, 3) << " s (95 % interval " << fmtNum(c.T_lo, 3) << "–"
         << fmtNum(c.T_hi, 3) << " s), sigma = " << fmtNum(p.sigma, 3) << " " << unit;
    else
      ex << ", " << stochastic::formatTerms({p}, 3) << " (" << unit << ", per sample at "
         << fmtNum(rate, 4) << " Hz)";
  }
  ex << ".";
  f.explanation = ex.str();
  f.action = "added to the model (model_extended.yaml); the filter gets it as " +
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
    *how = "gmwm (deviance " + fmtNum(dev0, 4) + " -> " + fmtNum(dev1, 4) + ")";
    return refit;
  }
  *how = "start kept (GMWM refit raised the deviance " + fmtNum(dev0, 4) + " -> " + fmtNum(dev1, 4) + ")";
  return start;
}

ChannelDiagnosis diagnoseChannel(Shared& sh, int ci) {
  const ImuChannel& chan = sh.data->channels[ci];
  const DiagnoseOptions& opt = *sh.opt;
  const double rate = sh.data->rate_hz;
  const std::size_t n = chan.x.size();
  ChannelDiagnosis cd;
  cd.name = chan.name;
  cd.model_before = sh.model->forChannel(chan.name);
  const Model& m0 = cd.model_before;
  const Budget& B = sh.per_channel;

  std::vector<double> x = chan.x;
  // Work on the mean-removed signal (a constant bias has no WV; better numerics).
  double mean = 0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  for (double& v : x) v -= mean;
  const std::vector<double> raw = x;

  // 1a. Spikes (Bonferroni over the samples, two-sided).
  const double z_sp = boost::math::quantile(boost::math::complement(
      boost::math::normal(), B.spikes / (2.0 * static_cast<double>(n))));
  const SpikeResult sp = detectSpikes(x, z_sp);
  if (!sp.index.empty()) {
    Finding f;
    f.channel = cd.name;
    f.cause = Cause::Outliers;
    f.params = {{"count", static_cast<double>(sp.index.size())}};
    double maxz = 0, maxa = 0;
    for (std::size_t i = 0; i < sp.index.size(); ++i) {
      const std::size_t k = sp.index[i];
      f.times_s.push_back(sh.data->t0_s + static_cast<double>(k) / rate);
      maxz = std::max(maxz, std::abs(sp.size[i]) / sp.scale);
      maxa = std::max(maxa, std::abs(sp.size[i]));
      x[k] = 0.5 * (x[k - 1] + x[k + 1]);
    }
    f.range_key = "t_s";
    f.range_lo = f.times_s.front();
    f.range_hi = f.times_s.back();
    f.statistic = maxz;
    f.threshold = z_sp;
    f.explanation = std::to_string(sp.index.size()) +
                    " isolated single-sample spike(s) up to " + fmtNum(maxa, 3) + " " +
                    channelUnit(cd.name) + " (" + fmtNum(maxz, 3) +
                    " robust sd of the second difference; family-wise threshold " +
                    fmtNum(z_sp, 3) +
                    "); Gaussian noise of the model does not produce them, and they "
                    "inflate the small-scale WV.";
    f.action = "do not model them as noise: remove or down-weight them (robust WV: "
               "`navimpact wv --robust`, robust GMWM); they were interpolated here before "
               "the WV analysis";
    cd.findings.push_back(f);
  }
  sh.tick(cd.name + ": spikes");

  // 1b. Level shifts.
  int levels = 0;
  const auto steps = detectSteps(x, B.steps, 5, &levels);
  for (const auto& s : steps) {
    Finding f;
    f.channel = cd.name;
    f.cause = Cause::LevelShift;
    const double t = sh.data->t0_s + static_cast<double>(s.index) / rate;
    f.params = {{"size", s.size}, {"t_s", t}};
    const double sc = std::ldexp(1.0, s.level) / rate;
    f.range_key = "scales_s";
    f.range_lo = sc;
    f.range_hi = sc;
    f.statistic = s.z;
    f.threshold = s.threshold;
    f.explanation = "a step of " + fmtNum(s.size, 3) + " " + channelUnit(cd.name) +
                    " at t = " + fmtNum(t, 5) + " s: the Haar coefficient at tau = " +
                    fmtNum(sc, 3) + " s there is " + fmtNum(s.z, 3) +
                    " robust sd (family-wise threshold " + fmtNum(s.threshold, 3) +
                    "); a random walk or Gauss-Markov process wanders but does not jump "
                    "once, and a step inflates the long-scale WV like a random walk.";
    f.action = "segment the record at t = " + fmtNum(t, 5) +
               " s (estimate the model on each segment) or remove the step; a stationary "
               "filter state cannot represent a one-off jump";
    cd.findings.push_back(f);
  }
  sh.tick(cd.name + ": level shifts");

  // 2. Spectral lines on the cleaned signal; model SIN frequencies excluded.
  std::size_t L = 16;
  while (L * 2 <= 16384 && L * 2 * 16 <= n) L *= 2;
  cd.spectrum = welch(x, rate, static_cast<int>(L));
  std::vector<LineResult> found_lines;
  {
    SpectrumCheck spec = cd.spectrum;
    for (int it = 0; it < 5; ++it) {
      auto lines = detectLines(x, rate, spec, B.spec);
      if (it == 0) cd.spectrum = spec;  // keep the first pass for plots
      const double bin = rate / static_cast<double>(L);
      lines.erase(std::remove_if(lines.begin(), lines.end(),
                                 [&](const LineResult& l) {
                                   for (const auto& t : m0.terms)
                                     if (t.kind == ProcessKind::SIN &&
                                         std::abs(t.freq_hz - l.freq_hz) < 4 * bin)
                                       return true;
                                   for (const auto& f : found_lines)
                                     if (std::abs(f.freq_hz - l.freq_hz) < 2 * bin) return true;
                                   return false;
                                 }),
                  lines.end());
      if (lines.empty()) break;
      auto strongest = *std::max_element(lines.begin(), lines.end(),
                                         [](const LineResult& a, const LineResult& b) {
                                           return a.ratio < b.ratio;
                                         });
      const LineResult ref = refineAndRemoveLine(x, rate, static_cast<int>(L), strongest);
      found_lines.push_back(ref);
      spec = welch(x, rate, static_cast<int>(L));
    }
  }
  for (const auto& l : found_lines) {
    cd.line_freqs_hz.push_back(l.freq_hz);
    Finding f;
    f.channel = cd.name;
    f.cause = Cause::Sinusoid;
    f.params = {{"amplitude", l.amplitude}, {"freq_hz", l.freq_hz}};
    const double bin = rate / static_cast<double>(L);
    f.range_key = "freq_hz";
    f.range_lo = l.freq_hz - bin;
    f.range_hi = l.freq_hz + bin;
    f.statistic = l.ratio;
    f.threshold = cd.spectrum.threshold_ratio;
    f.explanation = "the spectrum has a line at " + fmtNum(l.freq_hz, 5) + " Hz, " +
                    fmtNum(l.ratio, 3) + "x the broadband background (family-wise threshold " +
                    fmtNum(f.threshold, 3) + "x): a sinusoid of amplitude " +
                    fmtNum(l.amplitude, 3) + " " + channelUnit(cd.name) +
                    ", which the Haar WV smears around tau ≈ " + fmtNum(0.5 / l.freq_hz, 3) +
                    " s.";
    f.action = "added as SIN(amp, freq): a two-state oscillator in the filter (or notch it out "
               "if it is a vibration of the test bench)";
    cd.findings.push_back(f);
  }
  sh.tick(cd.name + ": spectrum");

  // 3. WV of the raw and cleaned record vs the model, with simulations.
  const auto wv_raw = gmwm::waveletVariance(raw.data(), n, rate);
  const auto wv_cl = gmwm::waveletVariance(x.data(), n, rate);
  const std::vector<double> tau = toStd(wv_raw.tau);
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
    // Moment-matched dof of the simulated ratios (var of chi2_eta / eta = 2 / eta);
    // used where fewer than eta3 (the theory would be over-confident there).
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
  auto chk_cl = checkScales(wv_cl, nu0, dof, p_thr, env_lo, env_hi);

  // 4. Cause of the broadband misfit: candidates on the first half, refit on all.
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
  WvData full{tau, toStd(wv_cl.wv), dof};
  WvData h1{toStd(wv_h1.tau), toStd(wv_h1.wv), halfDof(wv_h1)};

  Model m_full = m0, m_half = m0;
  int added_params = 0;
  std::map<int, std::size_t> added_by;  ///< term index added here -> its finding
  auto chk = chk_cl;
  for (int it = 0; it < opt.max_terms && countSignificant(chk) > 0; ++it) {
    auto cands = allCandidates(m_half, h1);
    int best = -1;
    double best_crit = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < cands.size(); ++i) {
      // AIC; retuning a term of the user's model discards what they had, so it
      // is charged as if it cost two more parameters (added terms keep the
      // parts that were right and are preferred unless clearly worse).
      double crit =
          cands[i].deviance + 2.0 * cands[i].params + (cands[i].retune ? 4.0 : 0.0);
      // A GM whose T the data do not bound from above (95 % profile interval
      // reaching the end of the grid, 10x the record) is a random walk over
      // this record: left to the RW candidate, which has one parameter less.
      if (!cands[i].retune && cands[i].kind == ProcessKind::GM && cands[i].T_hi_open)
        crit = std::numeric_limits<double>::infinity();
      if (crit < best_crit - 1e-9) {
        best_crit = crit;
        best = static_cast<int>(i);
      }
    }
    if (best < 0) break;
    const Candidate& ch = cands[best];
    // Stop when no family improves the first-half AIC of the current model.
    {
      Process pp = ch.proc;
      const double cur = wvDeviance(h1.nu, wvOf(m_half, h1.tau), h1.dof);
      if (!(mainParam(pp) > 0) || !(best_crit < cur)) break;
    }
    // Same family refitted on the whole (cleaned) record for the reported parameters.
    Candidate cf = fitCandidate(ch.retune, ch.term, ch.kind, m_full, full);
    const Model before = m_full;
    Finding nf = broadbandFinding(cd.name, cf, before, chk, tau, rate);
    double pmin = 1;
    for (const auto& s : chk) pmin = std::min(pmin, s.p_value);
    nf.statistic = pmin;
    nf.threshold = p_thr;
    // Retuning a term this diagnosis added itself refines that finding
    // (same cause, better parameters) instead of naming a new one.
    auto own = added_by.find(cf.retune ? cf.term : -1);
    if (cf.retune && own != added_by.end()) {
      Finding& old = cd.findings[own->second];
      old.params = nf.params;
      old.T_interval_s = nf.T_interval_s;
      if (cf.kind == ProcessKind::GM)
        old.explanation += " (refined after the next term: GM sigma = " +
                           fmtNum(cf.proc.sigma, 3) + ", T ≈ " + fmtNum(cf.proc.T, 3) + " s)";
    } else {
      cd.findings.push_back(nf);
      if (!cf.retune && !(cf.kind != ProcessKind::GM && m_full.count(cf.kind) > 0))
        added_by[static_cast<int>(m_full.terms.size())] = cd.findings.size() - 1;
    }
    m_full = applyCandidate(m_full, cf);
    m_half = applyCandidate(m_half, ch);
    added_params += ch.params;
    chk = checkScales(wv_cl, wvOf(m_full, tau), dof, p_thr, {}, {});
  }
  // GMWM refit of the extended structure, started from the user's parameters
  // plus the findings' estimates (gmwm::fit warm start: the refit never ends
  // above that start's GMWM objective), on the same data as the extension
  // (first half for the held-out model, whole cleaned record for the file).
  // The GMWM objective (fast weights) and the chi-square deviance that chose
  // the cause are different criteria: the refit is kept only when it does not
  // raise the deviance on the data it was fitted to (nothing held out is used).
  if (added_params > 0) {
    m_half = gmwmRefit(m_half, wv_h1, h1, &cd.refit_half);
    m_full = gmwmRefit(m_full, wv_cl, full, &cd.refit_full);
  }
  // Lines found in the spectrum become SIN terms of the extended model.
  for (const auto& l : found_lines) {
    m_full.terms.push_back(Process::sin(l.amplitude, l.freq_hz));
    m_half.terms.push_back(Process::sin(l.amplitude, l.freq_hz));
  }
  cd.model_after = m_full;
  cd.model_after_half = m_half;
  cd.wv_cleaned = toStd(wv_cl.wv);
  {
    // Extended model (without its SIN terms, subtracted from the cleaned data) vs cleaned WV.
    Model noline = m_full;
    noline.terms.erase(std::remove_if(noline.terms.begin(), noline.terms.end(),
                                      [&](const Process& p) {
                                        if (p.kind != ProcessKind::SIN) return false;
                                        for (const auto& l : found_lines)
                                          if (l.freq_hz == p.freq_hz) return true;
                                        return false;
                                      }),
                       noline.terms.end());
    cd.scales_after = checkScales(wv_cl, wvOf(noline, tau), dof, p_thr, {}, {});
  }
  cd.adequate = cd.findings.empty();

  // 5. Gain, held out: user's model on the raw second half vs the first-half
  // extension on the cleaned second half (lines, spikes, steps removed with
  // whole-record estimates). Without a fitted broadband term (cleaning or
  // lines only) nothing was fitted to the WV, and the whole record is used.
  GainCheck& g = cd.gain;
  const bool held_out = added_params > 0;
  g.basis = held_out ? "second_half" : "full_record";
  const gmwm::WaveletVariance& wb = held_out ? wv_h2r : wv_raw;
  const gmwm::WaveletVariance& wa = held_out ? wv_h2c : wv_cl;
  Model after_eval = held_out ? m_half : m_full;
  after_eval.terms.erase(std::remove_if(after_eval.terms.begin(), after_eval.terms.end(),
                                        [&](const Process& p) {
                                          if (p.kind != ProcessKind::SIN) return false;
                                          for (const auto& l : found_lines)
                                            if (l.freq_hz == p.freq_hz) return true;
                                          return false;
                                        }),
                         after_eval.terms.end());
  const auto tb = toStd(wb.tau), ta = toStd(wa.tau);
  const auto db = held_out ? halfDof(wb) : dof;
  const auto da = held_out ? halfDof(wa) : dof;
  const auto nub = wvOf(m0, tb), nua = wvOf(after_eval, ta);
  g.scales = wb.scales();
  g.added_params = added_params + 2 * static_cast<int>(found_lines.size());
  g.objective_before = m0.empty() ? kNaN : gmwm::objective(m0, wb);
  g.objective_after = after_eval.empty() ? kNaN : gmwm::objective(after_eval, wa);
  g.deviance_before = wvDeviance(toStd(wb.wv), nub, db);
  g.deviance_after = wvDeviance(toStd(wa.wv), nua, da);
  g.outside_before = countOutside(checkScales(wb, nub, db, p_thr, {}, {}));
  g.outside_after = countOutside(checkScales(wa, nua, da, p_thr, {}, {}));
  const double drop = g.deviance_before - g.deviance_after;
  if (drop > 0) {
    boost::math::chi_squared chi(std::max(1, g.added_params + (held_out ? 0 : 1)));
    g.p_value = boost::math::cdf(boost::math::complement(chi, drop));
  } else {
    g.p_value = 1;
  }
  g.significant = drop > 0 && g.p_value < 0.05;
  sh.tick(cd.name + ": model extension");
  return cd;
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
  if (std::abs(model.rate_hz - data.rate_hz) > 1e-9 * data.rate_hz) {
    d.model_before = stochastic::convertRate(model, data.rate_hz);
    d.notices.push_back("model " + model.source + " is at " + fmtNum(model.rate_hz, 6) +
                        " Hz, the data at " + fmtNum(data.rate_hz, 6) +
                        " Hz: converted exactly to the data rate (same continuous-time "
                        "processes)");
  }
  Shared sh;
  sh.data = &data;
  sh.model = &d.model_before;
  sh.opt = &opt;
  const double C = static_cast<double>(data.channels.size());
  sh.per_channel = {0.4 * opt.alpha / C, 0.2 * opt.alpha / C, 0.2 * opt.alpha / C,
                    0.2 * opt.alpha / C};
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
  return d;
}

}  // namespace navimpact::analysis
