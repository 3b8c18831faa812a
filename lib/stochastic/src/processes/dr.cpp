// DR(omega): deterministic drift (ramp), x_k = omega k, omega per sample at the model's rate.
#include <cmath>

#include "../kind.hpp"

namespace navimpact::stochastic::detail {

namespace {

class Drift final : public KindDef {
 public:
  const KindInfo& info() const override {
    static const KindInfo i{
        ProcessKind::DR, "DR",
        {{"omega", &Process::omega, "u/sample", false,
          [](double, double) { return std::make_pair(1e-12, 1e-3); }, "|omega| 1e-12 .. 1e-3 u"}},
        {}, SpectralForm::Trend, true};
    return i;
  }

  void convertRate(Process& p, double r) const override {
    // Same ramp slope in unit/s, omega/dt: omega_new = omega_old old/new.
    // Keeps omega^2 tau^2 / 16 = (omega rate)^2 tau_s^2 / 16 identical.
    p.omega /= r;
  }
  double conversionWvBound(const Process&, double, double, double) const override { return 0.0; }

  double haarWv(const Process& p, double, double tau) const override {
    return p.omega * p.omega * tau * tau / 16.0;  // omega^2 tau^2/16
  }

  void simulateAdd(const Process& p, double, Rng&, SimState& st, double* out, std::size_t n) const override {
    for (std::size_t k = 0; k < n; ++k) out[k] += p.omega * static_cast<double>(st.k + k);
    st.k += n;
  }

  int stateCount() const override { return 2; }
  void stateSpace(const Process& p, double rate_hz, StateSpaceBlock& b) const override {
    // [bias, rate]: bias' = rate, rate' = 0; the GMWM loses the drift's sign,
    // so the rate is a zero-mean prior of variance (omega/dt)^2 [unit/s]^2.
    const double dt = 1.0 / rate_hz;
    b.F(0, 1) = 1.0;
    b.H(0) = 1.0;
    b.P0(1, 1) = (p.omega / dt) * (p.omega / dt);
    b.names = {".bias", ".rate"};
  }

  // A ramp is neither a density nor a line (SpectralForm::Trend): no density().

  void addDatasheet(const Process& p, double rate_hz, DatasheetFigures& f) const override {
    // Drift rate omega / dt [u/s]; drifts add.
    const double dt = 1.0 / rate_hz;
    const double prev = f.drift_rate ? *f.drift_rate * dt : 0.0;
    f.drift_rate = (prev + p.omega) / dt;
  }
};

}  // namespace

const KindDef& kindDR() {
  static const Drift k;
  return k;
}

}  // namespace navimpact::stochastic::detail
