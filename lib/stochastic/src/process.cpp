// Latent processes, composite models, exact rate conversion and validation;
// what is specific to a kind is in processes/<name>.cpp.
#include "navimpact/stochastic/process.hpp"

#include <cmath>
#include <sstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/imu_series.hpp"
#include "kind.hpp"
#include "navimpact/stochastic/model_text.hpp"

namespace navimpact::stochastic {

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
  // Per kind (processes/<name>.cpp): the same continuous-time process at the new rate.
  for (auto& p : out.terms) detail::kindDef(p.kind).convertRate(p, r);
  return out;
}

double conversionWvBound(const Process& p, double rate_a_hz, double rate_b_hz, double tau_s) {
  return detail::kindDef(p.kind).conversionWvBound(p, rate_a_hz, rate_b_hz, tau_s);
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
    const detail::KindDef& def = detail::kindDef(p.kind);
    for (const ParamInfo& par : def.info().params) {
      const double v = p.*par.field;
      if (par.positive)
        requirePositive(m, i, par.key, v);
      else if (!std::isfinite(v))
        throw Error("model '" + formatTerms(m.terms) + "': " + termLabel(m, i) + ": " + par.key +
                    " must be finite");
      // An amplitude (a parameter in the signal's unit u) beyond the largest sample
      // any reader accepts is no IMU's (a WN sigma of 1e308 printed an ARW of inf,
      // and emulated rawlogs no reader took). Lower ends stay open: a fitted WN
      // sigma may legitimately be 1e-66.
      if (par.unit[0] == 'u' && std::abs(v) > kMaxAbsSpecificForce)
        throw Error("model '" + formatTerms(m.terms) + "': " + termLabel(m, i) + ": " + par.key + " = " +
                    formatNumber(v) + " is beyond any IMU (|" + par.key + "| <= " + formatNumber(kMaxAbsSpecificForce) +
                    " in SI, the largest sample the readers accept)");
    }
    const std::string msg = def.check(p, m.rate_hz);
    if (!msg.empty())
      throw Error("model '" + formatTerms(m.terms) + "': " + termLabel(m, i) + ": " + msg);
  }
}

std::vector<ProcessKind> Model::structure() const {
  std::vector<ProcessKind> k;
  k.reserve(terms.size());
  for (const auto& t : terms) k.push_back(t.kind);
  return k;
}

}  // namespace navimpact::stochastic
