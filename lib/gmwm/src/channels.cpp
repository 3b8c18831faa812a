// GMWM on every channel of a recording (see channels.hpp).
#include "navimpact/gmwm/channels.hpp"

#include <cmath>
#include <sstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/stochastic/datasheet.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

namespace navimpact::gmwm {

RecordingWv recordingWv(const ImuSeries& s, const WvOptions& opt, bool allan) {
  RecordingWv r;
  r.source = s.source;
  r.rate_hz = s.rate_hz;
  r.samples = s.size();
  r.options = opt;
  r.allan = allan;
  std::vector<WaveletVariance> wvs = waveletVariances(s, opt);
  // Cluster sizes m = 1, 2, 4, ... <= N/2 (IEEE Std 952 overlapping AVAR).
  std::vector<double> m;
  if (allan)
    for (double v = 1; v <= static_cast<double>(s.size() / 2); v *= 2) m.push_back(v);
  const Eigen::VectorXd mv = Eigen::Map<const Eigen::VectorXd>(m.data(), static_cast<Eigen::Index>(m.size()));
  for (std::size_t c = 0; c < s.channels.size(); ++c) {
    const ImuChannel& ch = s.channels[c];
    ChannelWv w;
    w.name = ch.name;
    w.quantity = ch.quantity;
    w.wv = std::move(wvs[c]);
    if (allan) {
      const Eigen::VectorXd avar = allanVariance(ch.x.data(), ch.x.size(), mv);
      for (std::size_t k = 0; k < m.size(); ++k) {
        w.allan_tau_s.push_back(m[k] / s.rate_hz);
        w.adev.push_back(std::sqrt(avar[static_cast<Eigen::Index>(k)]));
      }
    }
    r.channels.push_back(std::move(w));
  }
  return r;
}

namespace {

Weighting weightingOf(const std::string& w) {
  // r: the R package's objective (weights 1/(CI_hi - CI_lo)^2); model: iterated
  // model-based diagonal weights; efficient: inverse of the full WV covariance.
  if (w == "r") return Weighting::Fast;
  if (w == "model") return Weighting::ModelBased;
  if (w == "efficient") return Weighting::Efficient;
  throw Error("--weights: expected 'r', 'model' or 'efficient', got '" + printable(w, 60) + "'");
}

IntervalMethod intervalsOf(const std::string& i) {
  if (i == "profile") return IntervalMethod::Profile;
  if (i == "asymptotic") return IntervalMethod::Asymptotic;
  throw Error("--intervals: expected 'profile' or 'asymptotic', got '" + printable(i, 60) + "'");
}

std::vector<stochastic::ProcessKind> kindsOf(const stochastic::Model& m) {
  std::vector<stochastic::ProcessKind> k;
  for (const auto& t : m.terms) k.push_back(t.kind);
  return k;
}

}  // namespace

std::string whiteNoiseNote(const stochastic::Model& m, const std::vector<bool>& negligible) {
  if (negligible.size() != m.terms.size())
    throw Error("whiteNoiseNote: " + std::to_string(negligible.size()) + " flags for " +
                std::to_string(m.terms.size()) + " terms");
  const stochastic::DatasheetFigures d = stochastic::datasheetFigures(m);
  if (d.noise_density_gms == 0) return "";
  std::ostringstream os;
  os.precision(3);
  os << "white noise carried by ";
  int k = 0, gm = 0;
  bool wn_gone = true, has_wn = false;
  for (std::size_t i = 0; i < m.terms.size(); ++i) {
    const auto& t = m.terms[i];
    if (t.kind == stochastic::ProcessKind::WN) {
      has_wn = true;
      wn_gone = wn_gone && negligible[i];
    }
    if (t.kind != stochastic::ProcessKind::GM) continue;
    ++gm;
    const double samples = t.T * m.rate_hz;
    if (!(samples < stochastic::kWhiteGmMaxSamples)) continue;
    os << (k++ ? ", " : "") << "GM " << gm << " (T = " << t.T << " s = " << samples
       << " samples, lag-1 correlation " << std::exp(-1.0 / samples) << ")";
  }
  os << ": " << std::lround(100.0 * d.noise_density_gm_share) << " % of the noise density N^2";
  if (has_wn && wn_gone) os << ", the WN term is negligible";
  os << "; the ARW/VRW includes it, and a filter whose covariance step is longer than its T enters it as "
        "white noise of its long-run variance";
  return os.str();
}

std::string slowGmNote(const stochastic::Model& m, const WaveletVariance& wv) {
  const double record_s = static_cast<double>(wv.n) / m.rate_hz;
  const double bound_s = 1000.0 * record_s;  // the estimator's upper bound on T (estimator.cpp)
  std::ostringstream os, sig;
  os.precision(3);
  sig.precision(3);
  int gm = 0, k = 0;
  for (const auto& t : m.terms) {
    if (t.kind != stochastic::ProcessKind::GM) continue;
    ++gm;
    if (!(t.T >= record_s) || wv.scales() == 0) continue;
    // a GM's increment per sample, sqrt(1 - phi^2) sigma, is the equivalent RW's gamma
    const double gamma = t.sigma * std::sqrt(-std::expm1(-2.0 / (m.rate_hz * t.T)));
    const stochastic::Process rw = stochastic::Process::rw(gamma);
    bool same = true, visible = false;  // a GM the data cannot see at all is negligible, not a walk
    for (int j = 0; same && j < wv.scales(); ++j) {
      const double w = kNegligibleFraction * (wv.ci_high[j] - wv.ci_low[j]);
      const double g = stochastic::haarWv(t, m.rate_hz, wv.tau[j]);
      same = std::abs(g - stochastic::haarWv(rw, m.rate_hz, wv.tau[j])) < w;
      visible = visible || g >= w;
    }
    if (!same || !visible) continue;
    os << (k ? ", " : "") << "GM " << gm << " (T = " << t.T << " s = " << t.T / record_s << " records"
       << (t.T >= 0.999 * bound_s ? ", the fit's upper bound" : "") << ": RW(gamma=" << gamma << "))";
    sig << (k++ ? ", " : "") << t.sigma;
  }
  if (k == 0) return "";
  os << (k == 1 ? " is a random walk" : " are random walks")
     << " over this record (WV within " << kNegligibleFraction
     << " of the WV's 95 % CI width of that RW at every scale): the data fix sigma^2/T, not sigma (" << sig.str()
     << "), which a filter takes as the initial uncertainty; RW in the structure says what the data show";
  return os.str();
}

/// Most parametric bootstrap replicates of one fit (the intervals' 2.5 % and
/// 97.5 % quantiles are stable long before).
constexpr int kMaxBootstrap = 10000;

void checkRecordingFitOptions(const RecordingFitOptions& opt) {
  if (opt.structure != "auto") stochastic::parseStructure(opt.structure);
  if (opt.bootstrap < 0 || opt.bootstrap > kMaxBootstrap)
    throw Error("--bootstrap must be in [0, " + std::to_string(kMaxBootstrap) + "], got " + std::to_string(opt.bootstrap));
  if (opt.bootstrap > 0 && opt.bootstrap < kMinBootstrap)
    throw Error("--bootstrap must be 0 or at least " + std::to_string(kMinBootstrap) +
                " (a 95 % percentile interval needs (N + 1) * 0.025 >= 1), got " + std::to_string(opt.bootstrap));
  if (opt.max_gm < 0 || opt.max_gm > 3) throw Error("--max-gm must be in 0..3");
  try {
    checkRobustEfficiency(opt.eff);
  } catch (const Error& e) {
    throw Error(std::string("--eff: ") + e.what());
  }
  weightingOf(opt.weights);
  intervalsOf(opt.intervals);
  for (std::size_t i = 0; i < opt.channels.size(); ++i) {
    const std::string& n = opt.channels[i];
    if (channelIndex(n) < 0)
      throw Error("--channels: unknown channel '" + printable(n) +
                  "' (expected gyro_x, gyro_y, gyro_z, acc_x, acc_y, acc_z)");
    for (std::size_t j = 0; j < i; ++j)
      if (opt.channels[j] == n) throw Error("--channels: '" + n + "' is listed twice");
  }
}

RecordingFit fitRecording(const ImuSeries& s, const RecordingFitOptions& opt,
                          const std::function<void(std::size_t, std::size_t)>& progress) {
  checkRecordingFitOptions(opt);
  const bool autoSel = opt.structure == "auto";
  std::vector<stochastic::ProcessKind> structure;
  if (!autoSel) structure = stochastic::parseStructure(opt.structure);

  std::vector<const ImuChannel*> chans;
  if (opt.channels.empty()) {
    for (const auto& c : s.channels) chans.push_back(&c);
  } else {
    for (const auto& n : opt.channels) chans.push_back(&s.channel(n));
  }
  if (chans.empty()) throw Error(s.source + ": no IMU channel to fit");
  // each bootstrap replicate simulates the record and fits it again (README "Ranges and budgets")
  limits::checkBudget({{"fit: --bootstrap " + std::to_string(opt.bootstrap), "the bootstrap",
                        double(opt.bootstrap) * double(chans.size()) * double(s.size()),
                        limits::kDefaultSimulatedSampleBudget, "simulated samples",
                        std::to_string(chans.size()) + " channels x " + std::to_string(s.size()) + " samples",
                        "lower --bootstrap"}},
                      opt.allow_large);

  FitOptions fo;
  fo.bootstrap = opt.bootstrap;
  fo.intervals = intervalsOf(opt.intervals);
  fo.seed = opt.seed;
  fo.weighting = weightingOf(opt.weights);
  const auto cands = defaultCandidates(opt.max_gm);

  RecordingFit r;
  r.options = opt;
  r.source = s.source;
  r.rate_hz = s.rate_hz;
  r.samples = s.size();
  r.channels.resize(chans.size());
  for (std::size_t i = 0; i < chans.size(); ++i) {
    ChannelFit& c = r.channels[i];
    c.name = chans[i]->name;
    c.quantity = chans[i]->quantity;
    try {
      if (opt.robust) {
        std::vector<double> x = chans[i]->x;
        c.despiked = despike(x);
        c.wv = robustWaveletVariance(x.data(), x.size(), s.rate_hz, opt.eff);
      } else {
        c.wv = waveletVariance(chans[i]->x.data(), chans[i]->x.size(), s.rate_hz);
      }
    } catch (const Error& e) {
      throw Error(s.source + ": channel " + c.name + ": " + e.what());
    }
    FitOptions fi = fo;
    fi.seed = stochastic::deriveSeed(opt.seed, static_cast<std::uint64_t>(channelIndex(c.name)));
    try {
      if (autoSel) {
        // The WIC's optimism is derived for R's weights: rank with them, then
        // refit the pick with the requested weights.
        FitOptions fr = fi;
        fr.weighting = Weighting::Fast;
        c.ranking = selectModel(cands, c.wv, fr, &c.why);
        c.fit = c.ranking.front().fit;
        if (fi.weighting != Weighting::Fast) {
          fi.warm_starts = {c.fit.model};
          c.fit = fit(kindsOf(c.fit.model), c.wv, fi);
          c.why += "; ranked with the R weights, the pick refit with --weights " + opt.weights;
        }
      } else {
        c.fit = fit(structure, c.wv, fi);
      }
    } catch (const Error& e) {
      throw Error(s.source + ": channel " + c.name + ": " + e.what());
    }
    c.negligible = negligibleTerms(c.fit.model, c.wv);
    c.outside_ci = scalesOutsideCi(c.fit.model, c.wv);
    c.white_noise_note = whiteNoiseNote(c.fit.model, c.negligible);
    c.slow_gm_note = slowGmNote(c.fit.model, c.wv);
    if (progress) progress(i + 1, chans.size());
  }

  // Per-axis models at the data rate; channels not fitted stay "none".
  r.model.rate_hz = s.rate_hz;
  for (auto& m : r.model.axis) m.rate_hz = s.rate_hz;
  for (const auto& c : r.channels) {
    r.model.forChannel(c.name) = c.fit.model;
    r.model.forChannel(c.name).rate_hz = s.rate_hz;
  }
  return r;
}

}  // namespace navimpact::gmwm
