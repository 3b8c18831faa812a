// Detection power of navimpact diagnose (see diagnose_power.hpp).
#include "navimpact/analysis/diagnose_power.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <ctime>
#include <random>
#include <sstream>
#include <thread>

#include <boost/math/distributions/normal.hpp>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/core/parallel.hpp"
#include "navimpact/detect/null_model.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/stochastic/simulate.hpp"
#include "navimpact/stochastic/theoretical_wv.hpp"

namespace navimpact::analysis::power {

namespace {

constexpr double kPi = 3.14159265358979323846;

double zTwoSided(double p) {
  return boost::math::quantile(boost::math::complement(boost::math::normal(), 0.5 * p));
}

struct Rng {
  std::mt19937_64 g;
  explicit Rng(std::uint64_t s) : g(s) {}
  double u() { return std::uniform_real_distribution<double>(0, 1)(g); }
  double logU(double a, double b) { return a * std::pow(b / a, u()); }
  std::uint64_t next() { return g(); }
};

double wvAt(const stochastic::Model& m, double tau) {
  double v = 0;
  for (const auto& p : m.terms) v += stochastic::haarWv(p, m.rate_hz, tau);
  return v;
}

/// Scale a of a unit process so that its WV excess over @p m reaches
/// @p target standard errors of the WV at the best dyadic scale.
double wvScaleFor(const stochastic::Process& unit, const stochastic::Model& m, std::size_t n, double target) {
  double best = 0;
  for (int j = 1; std::ldexp(1.0, j) <= static_cast<double>(n) / 2; ++j) {
    const double tau = std::ldexp(1.0, j);
    const double M = static_cast<double>(n) - tau + 1;
    const double eta = std::max(M / tau, 1.0);
    const double r = stochastic::haarWv(unit, m.rate_hz, tau) / wvAt(m, tau) * std::sqrt(eta / 2.0);
    best = std::max(best, r);
  }
  return best > 0 ? target / best : 0.0;
}

/// Detection limits (see the header), for a six-channel record at alpha 1 %.
constexpr double kAlpha = 0.01, kChannels = 6;

double wvLimit(std::size_t n) {
  const double J = std::floor(std::log2(static_cast<double>(n)));
  return zTwoSided(0.4 * kAlpha / (kChannels * J));
}

/// Stated identification limits of the slow processes, in units of the WV
/// test's threshold (their excess sits in the coarsest scales, which have the
/// fewest degrees of freedom and where random walk, drift and long
/// Gauss-Markov look alike): measured with navimpact diagnose-power (README).
double wvLimitFactor(Cause c) {
  switch (c) {
    case Cause::RandomWalk:
    case Cause::Drift: return 4.0;
    case Cause::GaussMarkov: return 6.0;
    default: return 1.0;
  }
}

double lineLimit(const stochastic::Model& m, double f, std::size_t n) {
  const double c = std::log(0.5 * static_cast<double>(n) / (0.2 * kAlpha / kChannels));
  const double S = detect::psdOf(m)(f);
  return std::sqrt(6.0 * c * S * m.rate_hz / (0.72 * static_cast<double>(n)));
}

double stepLimit(const stochastic::Model& m, std::size_t n, std::size_t k0) {
  std::vector<std::size_t> ms;
  for (double mf = 8; 2 * std::floor(mf) <= static_cast<double>(n); mf *= std::sqrt(2.0))
    if (ms.empty() || ms.back() != static_cast<std::size_t>(mf)) ms.push_back(static_cast<std::size_t>(mf));
  double limit = INFINITY;
  for (std::size_t mm : ms) {
    if (mm > std::min(k0, n - k0)) continue;
    const double P = static_cast<double>((n - 2 * mm) / std::max<std::size_t>(1, mm / 8) + 1);
    const double thr = zTwoSided(0.2 * kAlpha / kChannels / (static_cast<double>(ms.size()) * P));
    limit = std::min(limit, thr * 2.0 * std::sqrt(wvAt(m, 2.0 * static_cast<double>(mm))));
  }
  return limit;
}

double outlierLimit(const stochastic::Model& m, std::size_t n) {
  return zTwoSided(0.2 * kAlpha / kChannels / static_cast<double>(n - 2)) * detect::secondDifferenceSd(m);
}

bool within(double est, double truth, double rel) {
  return std::isfinite(est) && std::abs(est - truth) <= rel * std::abs(truth);
}

/// The finding's reported 95 % interval of @p key holds @p truth.
bool covers(const Finding& f, const std::string& key, double truth) {
  for (const auto& kv : f.intervals)
    if (kv.first == key) return kv.second.first <= truth && truth <= kv.second.second;
  return false;
}

}  // namespace

double Hidden::get(const std::string& key) const {
  for (const auto& kv : truth)
    if (kv.first == key) return kv.second;
  return NAN;
}

Case drawCase(const std::vector<Cause>& causes, const DrawRanges& rg, double snr_factor, std::uint64_t seed,
              int channels) {
  if (channels != 1 && channels != 6) throw Error("drawCase: channels must be 1 or 6");
  Rng rng(seed);
  Case c;
  const double rate = rng.logU(rg.min_rate_hz, rg.max_rate_hz);
  std::size_t n;
  if (rg.max_duration_s > 0) n = static_cast<std::size_t>(rng.logU(rg.min_duration_s, rg.max_duration_s) * rate);
  else n = static_cast<std::size_t>(rng.logU(static_cast<double>(rg.min_samples), static_cast<double>(rg.max_samples)));
  n = std::max<std::size_t>(n, 4096);
  const double record = static_cast<double>(n) / rate;
  c.data.source = "simulated";
  c.data.rate_hz = rate;
  c.model.rate_hz = rate;
  c.model.source = "drawn";
  const int first = channels == 1 ? static_cast<int>(rng.next() % 6) : 0;
  std::ostringstream txt;
  txt << "rate=" << formatNumber(rate, 5) << " Hz n=" << n << " (" << formatNumber(record, 4) << " s)";
  for (int q = 0; q < channels; ++q) {
    const int ci = channels == 1 ? first : q;
    stochastic::Model& m = c.model.axis[ci];
    m.rate_hz = rate;
    const double sw = rng.logU(rg.min_wn, rg.max_wn);
    m.terms = {stochastic::Process::wn(sw)};
    const int base = static_cast<int>(rng.next() % 3);
    if (base == 1) {
      const double T = rng.logU(2.0 / rate, record / 5.0);
      // GM WV peak rho x the white noise's there.
      double peak = 0;
      for (int j = 1; std::ldexp(1.0, j) <= n / 2.0; ++j) {
        const double tau = std::ldexp(1.0, j);
        peak = std::max(peak, stochastic::haarWv(stochastic::Process::gm(1.0, T), rate, tau) / (sw * sw / tau));
      }
      m.terms.push_back(stochastic::Process::gm(std::sqrt(rng.logU(0.1, 1.0) / peak), T));
    } else if (base == 2) {
      // RW WV crosses the white noise's at tau_c in [N/16, 4N].
      const double tc = rng.logU(n / 16.0, 4.0 * n);
      m.terms.push_back(stochastic::Process::rw(sw * std::sqrt(12.0) / tc));
    }
    ImuChannel ch;
    ch.name = kChannelNames[ci];
    ch.quantity = channelQuantity(ch.name);
    ch.x = stochastic::simulate(m, n, stochastic::deriveSeed(seed, 100 + ci));
    ch.x.resize(n);
    const double bias = ci == 5 ? -9.81 : 0.01 * (ci + 1);
    for (double& v : ch.x) v += bias;
    c.data.channels.push_back(std::move(ch));
    if (q == 0 || channels == 1) txt << " " << kChannelNames[ci] << ": " << stochastic::formatTerms(m.terms, 3);
  }
  c.channel = channels == 1 ? 0 : static_cast<int>(rng.next() % 6);
  const int ci = channels == 1 ? first : c.channel;
  const stochastic::Model& base = c.model.axis[ci];
  auto& x_out = c.data.channels[c.channel].x;
  // Each effect's size is a multiple of its limit in the noise it sits in:
  // the base model plus the other effects' random (and drift) parts. Pass 1
  // sizes every effect against the base model alone; pass 2 draws the same
  // shapes (same random stream) and sizes each against the base plus the
  // others' pass-1 processes, and writes the record. One effect: the base.
  std::vector<std::optional<stochastic::Process>> noise_of(causes.size());
  const Rng rng_start = rng;
  std::vector<double> scratch(n, 0.0);
  const int passes = causes.size() > 1 ? 2 : 1;
  for (int pass = 0; pass < passes; ++pass) {
  const bool last = pass == passes - 1;
  rng = rng_start;
  std::vector<std::optional<stochastic::Process>> noise_now(causes.size());
  auto& x = last ? x_out : scratch;
  for (std::size_t e = 0; e < causes.size(); ++e) {
    stochastic::Model m = base;
    if (pass > 0)
      for (std::size_t o = 0; o < causes.size(); ++o)
        if (o != e && noise_of[o]) m.terms.push_back(*noise_of[o]);
    Hidden h;
    h.cause = causes[e];
    h.snr = snr_factor;
    const std::uint64_t ps = stochastic::deriveSeed(seed, 200 + e);
    auto addProc = [&](const stochastic::Process& p) {
      noise_now[e] = p;
      if (!last) return;
      stochastic::Model mm;
      mm.rate_hz = rate;
      mm.terms = {p};
      stochastic::simulateAdd(mm, ps, x.data(), n);
    };
    const double target = snr_factor * wvLimitFactor(h.cause) * wvLimit(n);
    switch (h.cause) {
      case Cause::WhiteNoise: {
        const double s = std::sqrt(wvScaleFor(stochastic::Process::wn(1.0), m, n, target));
        addProc(stochastic::Process::wn(s));
        h.truth = {{"sigma", s}, {"sigma_total", std::hypot(s, m.terms[0].sigma)}};
        break;
      }
      case Cause::QuantizationNoise: {
        const double Q = std::sqrt(wvScaleFor(stochastic::Process::qn(1.0), m, n, target));
        addProc(stochastic::Process::qn(Q));
        h.truth = {{"Q", Q}};
        break;
      }
      case Cause::RandomWalk: {
        const double g = std::sqrt(wvScaleFor(stochastic::Process::rw(1.0), m, n, target));
        addProc(stochastic::Process::rw(g));
        double total = g;
        for (const auto& p : m.terms)
          if (p.kind == stochastic::ProcessKind::RW) total = std::hypot(g, p.gamma);
        h.truth = {{"gamma", g}, {"gamma_total", total}};
        break;
      }
      case Cause::Drift: {
        const double w = std::sqrt(wvScaleFor(stochastic::Process::dr(1.0), m, n, target));
        const double sign = rng.u() < 0.5 ? -1.0 : 1.0;
        noise_now[e] = stochastic::Process::dr(w);
        if (last)
          for (std::size_t k = 0; k < n; ++k) x[k] += sign * w * static_cast<double>(k);
        h.truth = {{"omega", w}};
        break;
      }
      case Cause::GaussMarkov: {
        const double T = rng.logU(std::max(2.0 / rate, rg.min_gm_T_record * record), record / 5.0);
        const double s = std::sqrt(wvScaleFor(stochastic::Process::gm(1.0, T), m, n, target));
        addProc(stochastic::Process::gm(s, T));
        h.truth = {{"sigma", s}, {"T", T}};
        break;
      }
      case Cause::Sinusoid: {
        const double f = rng.logU(5.0 / record, 0.45 * rate);
        const double a = snr_factor * lineLimit(m, f, n);
        const double ph = 2 * kPi * rng.u();
        if (last)
          for (std::size_t k = 0; k < n; ++k) x[k] += a * std::sin(2 * kPi * f * static_cast<double>(k) / rate + ph);
        h.truth = {{"amplitude", a}, {"freq_hz", f}};
        break;
      }
      case Cause::LevelShift: {
        const std::size_t k0 = static_cast<std::size_t>((0.1 + 0.8 * rng.u()) * static_cast<double>(n));
        const double size = (rng.u() < 0.5 ? -1.0 : 1.0) * snr_factor * stepLimit(m, n, k0);
        if (last)
          for (std::size_t k = k0; k < n; ++k) x[k] += size;
        h.truth = {{"size", size}, {"t_s", static_cast<double>(k0) / rate}};
        break;
      }
      case Cause::Outliers: {
        const double height = snr_factor * outlierLimit(m, n);
        const int count = 1 + static_cast<int>(rng.next() % 20);
        std::vector<std::size_t> at;
        for (int i = 0; i < count; ++i) {
          std::size_t k = 0;
          for (int tries = 0; tries < 1000; ++tries) {
            k = 100 + rng.next() % (n - 200);
            bool ok = true;
            for (auto a : at) ok = ok && (k > a + 200 || a > k + 200);
            if (ok) break;
          }
          at.push_back(k);
          const int len = rng.u() < 0.5 ? 1 : 2 + static_cast<int>(rng.next() % 19);
          const double sign = rng.u() < 0.5 ? -1.0 : 1.0;
          if (last)
            for (int j = 0; j < len; ++j) x[k + j] += (j % 2 ? -1.0 : 1.0) * sign * height;
        }
        h.events = count;
        h.truth = {{"count", static_cast<double>(count)}};
        break;
      }
    }
    if (!last) continue;
    txt << " | hidden " << causeName(h.cause) << " at " << formatNumber(snr_factor, 3) << "x limit";
    if (causes.size() > 1) txt << " (with the other effect as noise)";
    txt << ":";
    for (const auto& kv : h.truth) txt << " " << kv.first << "=" << formatNumber(kv.second, 4);
    c.hidden.push_back(h);
  }
  noise_of = noise_now;
  }
  c.text = txt.str();
  return c;
}

std::string describe(const Diagnosis& d) {
  std::string s;
  for (const auto& c : d.channels)
    for (const auto& f : c.findings) {
      s += " [" + c.name + " " + causeName(f.cause);
      for (const auto& kv : f.params) s += " " + kv.first + "=" + formatNumber(kv.second, 4);
      if (!f.decided) s += " undecided vs " + f.runner_up;
      s += "]";
    }
  return s;
}

Outcome judge(const Case& c, const Diagnosis& d) {
  Outcome o;
  std::ostringstream why;
  const double record = static_cast<double>(c.data.size()) / c.data.rate_hz;
  const double bin = c.data.rate_hz / static_cast<double>(c.data.size());
  for (std::size_t q = 0; q < d.channels.size(); ++q)
    if (static_cast<int>(q) != c.channel && !d.channels[q].findings.empty())
      why << "spurious finding on " << d.channels[q].name << "; ";
  const auto& cd = d.channels[c.channel];
  for (const auto& h : c.hidden) {
    const bool det = !cd.findings.empty();
    bool right = false;
    std::string last = std::string("no ") + causeName(h.cause);
    for (const auto& f : cd.findings) {
      if (f.cause != h.cause) continue;
      std::string bad;
      switch (h.cause) {
        case Cause::WhiteNoise:
          if (!within(f.get("sigma"), h.get("sigma"), 0.3) && !within(f.get("sigma"), h.get("sigma_total"), 0.3)) bad = "sigma off";
          break;
        case Cause::QuantizationNoise:
          if (!within(f.get("Q"), h.get("Q"), 0.3)) bad = "Q off";
          break;
        case Cause::RandomWalk:
          if (!within(f.get("gamma"), h.get("gamma"), 0.3) && !within(f.get("gamma"), h.get("gamma_total"), 0.3) &&
              !covers(f, "gamma", h.get("gamma")) && !covers(f, "gamma", h.get("gamma_total")))
            bad = "gamma off";
          break;
        case Cause::Drift:
          if (!within(std::abs(f.get("omega")), h.get("omega"), 0.3) && !covers(f, "omega", h.get("omega")))
            bad = "omega off";
          break;
        case Cause::GaussMarkov: {
          const double r = f.get("T") / h.get("T");
          if (!(r >= 1 / 1.5 && r <= 1.5)) bad = "T off";
          break;
        }
        case Cause::Sinusoid:
          if (!(std::abs(f.get("freq_hz") - h.get("freq_hz")) <= 2 * bin)) bad = "freq off";
          else if (!within(f.get("amplitude"), h.get("amplitude"), 0.3)) bad = "amplitude off";
          break;
        case Cause::LevelShift:
          if (!(std::abs(f.get("t_s") - h.get("t_s")) <= 0.02 * record)) bad = "t_s off";
          else if (!within(f.get("size"), h.get("size"), 0.3)) bad = "size off";
          break;
        case Cause::Outliers:
          if (f.get("count") != h.get("count")) bad = "count off";
          break;
      }
      if (bad.empty()) right = true;
      else last = bad;
    }
    // Nothing else on the channel: one finding per hidden effect (a level
    // shift hidden once may not come back as several).
    if (right && cd.findings.size() != c.hidden.size()) {
      right = false;
      last = std::to_string(cd.findings.size()) + " findings for " + std::to_string(c.hidden.size()) + " effect(s)";
    }
    if (!why.str().empty()) right = false;
    o.detected.push_back(det);
    o.right.push_back(right);
    if (!right) why << cd.name << ": " << last << "; ";
  }
  if (!why.str().empty()) o.why = why.str() + "truth: " + c.text + " found:" + describe(d);
  return o;
}

namespace {
std::vector<Cause> allCauses() {
  return {Cause::WhiteNoise, Cause::QuantizationNoise, Cause::RandomWalk, Cause::Drift,
          Cause::GaussMarkov, Cause::Sinusoid, Cause::LevelShift, Cause::Outliers};
}
}  // namespace

namespace {
// a record's six channels and their workspace: ~3 doubles per sample and channel
// (measured: a null record of 1e6 samples peaks 88 MB above one of 2.5e5)
constexpr double kPowerBytesPerSample = 6.0 * 3.0 * 8.0;
}  // namespace

unsigned powerThreads(const PowerOptions& opt) {
  if (opt.threads > 0) return unsigned(opt.threads);
  const double hw = std::max(1u, std::thread::hardware_concurrency());
  const DrawRanges& r = opt.ranges;
  const double nMax = r.max_duration_s > 0 ? r.max_duration_s * r.max_rate_hz : double(r.max_samples);
  return limits::budgetWorkers(hw, nMax, 0.0, kPowerBytesPerSample);
}

void checkPowerOptions(const PowerOptions& opt) {
  const auto fail = [](const std::string& what) { throw Error("diagnose-power: " + what); };
  const long long maxRuns = limits::kMaxMonteCarloRuns;
  if (opt.runs_per_cause < 0 || opt.runs_per_cause > maxRuns || opt.null_runs < 0 || opt.null_runs > maxRuns)
    fail("--runs and --null-runs must be in [0, " + std::to_string(maxRuns) + "], got " +
         std::to_string(opt.runs_per_cause) + " and " + std::to_string(opt.null_runs));
  const std::size_t causes = opt.causes.empty() ? allCauses().size() : opt.causes.size();
  const double records = double(opt.runs_per_cause) * double(causes) + double(opt.null_runs);
  if (records < 1) fail("--runs and --null-runs are both 0: no record to diagnose");
  for (std::size_t i = 0; i < opt.causes.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (opt.causes[i] == opt.causes[j]) fail(std::string("--causes: '") + causeName(opt.causes[i]) + "' is listed twice");
  if (!(opt.min_snr > 0 && opt.max_snr >= opt.min_snr && opt.max_snr <= 1000))
    fail("--snr must be LO:HI with 0 < LO <= HI <= 1000, got " + formatNumber(opt.min_snr) + ":" + formatNumber(opt.max_snr));
  const DrawRanges& r = opt.ranges;
  if (!(r.min_rate_hz >= limits::kImuRateHz.lo && r.max_rate_hz <= limits::kImuRateHz.hi && r.min_rate_hz <= r.max_rate_hz))
    fail("--rate must lie in " + limits::describe(limits::kImuRateHz) + ", got " + formatNumber(r.min_rate_hz) + ":" +
         formatNumber(r.max_rate_hz));
  // the smallest and largest record [samples]
  double nMin = double(r.min_samples), nMax = double(r.max_samples);
  std::string lengthFlag = "--samples";
  if (r.max_duration_s > 0) {
    nMin = r.min_duration_s * r.min_rate_hz;
    nMax = r.max_duration_s * r.max_rate_hz;
    lengthFlag = "--duration-h";
  }
  if (!(nMin >= 4096 && nMax >= nMin))
    fail(lengthFlag + ": the shortest record would have " + formatNumber(nMin, 3) +
         " samples (at least 4096: the diagnosis's wavelet variance needs 12 scales)");
  if (opt.threads < 0 || opt.threads > 1024) fail("--threads must be in [0, 1024], got " + std::to_string(opt.threads));
  if (opt.simulations < 0 || opt.simulations == 1 || opt.simulations > maxRuns)
    fail("--simulations must be 0 or in [2, " + std::to_string(maxRuns) + "], got " + std::to_string(opt.simulations));
  // six channels on null records, one otherwise; each simulated (1 + simulations) times
  const double work = (double(opt.runs_per_cause) * double(causes) + 6.0 * double(opt.null_runs)) * nMax *
                      (1.0 + double(opt.simulations));
  const double workers = std::min(double(powerThreads(opt)), records);
  const double bytes = workers * nMax * kPowerBytesPerSample;
  limits::checkBudget({{"diagnose-power", "the records", work, limits::kDefaultSimulatedSampleBudget, "simulated samples",
                        formatNumber(records, 3) + " records x " + formatNumber(nMax, 3) + " samples x " +
                            std::to_string(1 + opt.simulations),
                        "lower --runs, --null-runs, --simulations or " + lengthFlag},
                       {"diagnose-power", "the records held at once", bytes / 1e6, limits::kDefaultMemoryBudgetBytes / 1e6,
                        "MB", formatNumber(workers) + " workers", "lower " + lengthFlag + " or --threads"}},
                      opt.allow_large);
}

PowerResult runPower(const PowerOptions& opt_in) {
  checkPowerOptions(opt_in);
  PowerOptions opt = opt_in;
  if (opt.causes.empty()) opt.causes = allCauses();
  PowerResult res;
  res.options = opt;
  struct Job {
    int cause;  // -1 null
    int index;
  };
  std::vector<Job> jobs;
  for (int i = 0; i < opt.null_runs; ++i) jobs.push_back({-1, i});
  for (std::size_t c = 0; c < opt.causes.size(); ++c)
    for (int i = 0; i < opt.runs_per_cause; ++i) jobs.push_back({static_cast<int>(c), i});
  std::vector<PowerRun> out(jobs.size());
  std::vector<char> alarm(jobs.size(), 0);
  const auto wall0 = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();
  TaskProgress progress;
  if (opt.progress)
    progress = [&](std::size_t done, std::size_t count) {
      opt.progress(static_cast<double>(done) / static_cast<double>(count));
    };
  try {
    parallelFor(jobs.size(), powerThreads(opt), [&](std::size_t i) {
      const Job& j = jobs[i];
      const std::uint64_t s = stochastic::deriveSeed(opt.seed, 1000000u * static_cast<std::uint64_t>(j.cause + 1) + j.index);
      Rng rng(stochastic::deriveSeed(s, 1));
      const double snr = j.cause < 0 ? 0.0 : rng.logU(opt.min_snr, opt.max_snr);
      const std::vector<Cause> cs = j.cause < 0 ? std::vector<Cause>{} : std::vector<Cause>{opt.causes[j.cause]};
      const Case c = drawCase(cs, opt.ranges, snr, s, j.cause < 0 ? 6 : 1);
      DiagnoseOptions dopt;
      dopt.seed = s;
      dopt.threads = 1;
      dopt.simulations = opt.simulations;
      dopt.alpha = opt.alpha;
      const Diagnosis d = diagnose(c.data, c.model, dopt);
      PowerRun& r = out[i];
      r.rate_hz = c.data.rate_hz;
      r.duration_s = static_cast<double>(c.data.size()) / c.data.rate_hz;
      r.snr = snr;
      if (j.cause < 0) {
        alarm[i] = !d.adequate;
        if (!d.adequate) r.why = c.text + ":" + describe(d);
      } else {
        const Outcome o = judge(c, d);
        r.cause = opt.causes[j.cause];
        r.detected = o.detected[0];
        r.right = o.right[0];
        r.why = o.why;
      }
    }, progress);
  } catch (const Error& e) {
    throw Error("diagnose-power: " + std::string(e.what()));
  }
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    if (jobs[i].cause < 0) {
      ++res.null_runs;
      res.null_alarms += alarm[i];
    } else {
      res.runs.push_back(out[i]);
    }
  }
  res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  res.cpu_s = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  return res;
}

}  // namespace navimpact::analysis::power
