// Latent processes, composite models, exact rate conversion and validation.
#include "navimpact/stochastic/process.hpp"

#include <cmath>
#include <sstream>

#include "navimpact/core/error.hpp"
#include "navimpact/stochastic/model_text.hpp"

namespace navimpact::stochastic {

const char* kindName(ProcessKind k) {
  switch (k) {
    case ProcessKind::WN: return "WN";
    case ProcessKind::QN: return "QN";
    case ProcessKind::RW: return "RW";
    case ProcessKind::DR: return "DR";
    case ProcessKind::GM: return "GM";
    case ProcessKind::SIN: return "SIN";
  }
  return "?";
}

Process Process::wn(double sigma) {
  Process p;
  p.kind = ProcessKind::WN;
  p.sigma = sigma;
  return p;
}

Process Process::qn(double Q) {
  Process p;
  p.kind = ProcessKind::QN;
  p.Q = Q;
  return p;
}

Process Process::rw(double gamma) {
  Process p;
  p.kind = ProcessKind::RW;
  p.gamma = gamma;
  return p;
}

Process Process::dr(double omega) {
  Process p;
  p.kind = ProcessKind::DR;
  p.omega = omega;
  return p;
}

Process Process::gm(double sigma, double T) {
  Process p;
  p.kind = ProcessKind::GM;
  p.sigma = sigma;
  p.T = T;
  return p;
}

Process Process::sin(double amp, double freq_hz) {
  Process p;
  p.kind = ProcessKind::SIN;
  p.amp = amp;
  p.freq_hz = freq_hz;
  return p;
}

Process Process::ar1(double phi, double sigma2_innov, double rate_hz) {
  if (!(phi > 0.0 && phi < 1.0))
    throw Error("AR1(phi=" + std::to_string(phi) +
                "): phi must be in (0, 1) to be a Gauss-Markov process");
  if (!(sigma2_innov > 0.0) || !std::isfinite(sigma2_innov))
    throw Error("AR1: sigma2 must be a finite number > 0");
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz))
    throw Error("AR1: a positive rate_hz is needed to convert AR1 to GM");
  // phi = exp(-dt/T)  =>  T = -dt / ln(phi); ln(phi) = log1p(phi - 1) is exact
  // for phi near 1 because phi - 1 is computed without rounding (Sterbenz).
  const double dt = 1.0 / rate_hz;
  const double T = -dt / std::log1p(phi - 1.0);
  // Stationary variance of x_k = phi x_{k-1} + e_k: sigma2 / (1 - phi^2).
  const double one_minus_phi2 = (1.0 - phi) * (1.0 + phi);
  return gm(std::sqrt(sigma2_innov / one_minus_phi2), T);
}

bool Process::operator==(const Process& o) const {
  return kind == o.kind && sigma == o.sigma && Q == o.Q && gamma == o.gamma &&
         omega == o.omega && T == o.T && amp == o.amp && freq_hz == o.freq_hz;
}

int Model::count(ProcessKind k) const {
  int c = 0;
  for (const auto& t : terms)
    if (t.kind == k) ++c;
  return c;
}

Model convertRate(const Model& m, double new_rate_hz) {
  if (!(m.rate_hz > 0.0) || !std::isfinite(m.rate_hz))
    throw Error("convertRate: model has no valid rate_hz");
  if (!(new_rate_hz > 0.0) || !std::isfinite(new_rate_hz))
    throw Error("convertRate: new rate must be a finite number > 0 Hz");
  const double r = new_rate_hz / m.rate_hz;  // new / old
  Model out;
  out.rate_hz = new_rate_hz;
  out.terms = m.terms;
  for (auto& p : out.terms) {
    switch (p.kind) {
      case ProcessKind::WN:
        // Same white-noise density N = sigma sqrt(dt): sigma_new^2 dt_new =
        // sigma_old^2 dt_old  =>  sigma_new = sigma_old sqrt(new/old). Keeps the
        // WV in seconds, sigma^2/(tau_s rate), identical at every scale.
        p.sigma *= std::sqrt(r);
        break;
      case ProcessKind::QN:
        // Same quantization Q_c = Q dt (unit*s): Q_new = Q_old new/old. Keeps
        // 6 Q^2 / tau^2 = 6 Q^2 / (tau_s rate)^2 identical.
        p.Q *= r;
        break;
      case ProcessKind::RW:
        // Same continuous random walk K = gamma / sqrt(dt): gamma_new =
        // gamma_old sqrt(old/new). Keeps the dominant gamma^2 tau / 12 =
        // K^2 tau_s / 12 identical; the finite-sample 2 gamma^2/(12 tau) term
        // is not invariant (it is O(dt/tau_s)^2 relative).
        p.gamma /= std::sqrt(r);
        break;
      case ProcessKind::DR:
        // Same ramp slope in unit/s, omega/dt: omega_new = omega_old old/new.
        // Keeps omega^2 tau^2 / 16 = (omega rate)^2 tau_s^2 / 16 identical.
        p.omega /= r;
        break;
      case ProcessKind::GM:
        // The same continuous GM process (stationary sigma, correlation time T
        // in seconds) sampled at another rate: both unchanged, phi = exp(-dt/T)
        // follows dt. (Its discrete Haar WV in seconds is invariant only up to
        // O((dt/T)^2) and O(dt/tau_s)^2 sampling effects.)
        break;
      case ProcessKind::SIN:
        // The same sinusoid (amplitude in the signal's unit, frequency in Hz).
        break;
    }
  }
  return out;
}

namespace {
std::string termLabel(const Model& m, std::size_t i) {
  std::ostringstream os;
  os << "term " << (i + 1) << " " << formatTerms({m.terms[i]});
  return os.str();
}

void requirePositive(const Model& m, std::size_t i, const char* key, double v) {
  if (!std::isfinite(v) || !(v > 0.0))
    throw Error("model '" + formatTerms(m.terms) + "': " + termLabel(m, i) + ": " + key +
                " must be a finite number > 0");
}
}  // namespace

void validate(const Model& m) {
  if (m.terms.empty()) return;
  if (!(m.rate_hz > 0.0) || !std::isfinite(m.rate_hz))
    throw Error("model '" + formatTerms(m.terms) + "': rate_hz must be a finite number > 0");
  for (std::size_t i = 0; i < m.terms.size(); ++i) {
    const Process& p = m.terms[i];
    switch (p.kind) {
      case ProcessKind::WN: requirePositive(m, i, "sigma", p.sigma); break;
      case ProcessKind::QN: requirePositive(m, i, "Q", p.Q); break;
      case ProcessKind::RW: requirePositive(m, i, "gamma", p.gamma); break;
      case ProcessKind::DR:
        if (!std::isfinite(p.omega))
          throw Error("model '" + formatTerms(m.terms) + "': " + termLabel(m, i) +
                      ": omega must be finite");
        break;
      case ProcessKind::GM:
        requirePositive(m, i, "sigma", p.sigma);
        requirePositive(m, i, "T", p.T);
        break;
      case ProcessKind::SIN:
        requirePositive(m, i, "amp", p.amp);
        requirePositive(m, i, "freq", p.freq_hz);
        if (!(p.freq_hz < 0.5 * m.rate_hz))
          throw Error("model '" + formatTerms(m.terms) + "': " + termLabel(m, i) +
                      ": freq must be below the Nyquist frequency rate_hz/2 = " +
                      std::to_string(0.5 * m.rate_hz) + " Hz");
        break;
    }
  }
}

}  // namespace navimpact::stochastic
