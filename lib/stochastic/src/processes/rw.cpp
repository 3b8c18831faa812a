// RW(gamma): random walk, x_k = x_{k-1} + gamma z_k, gamma per sample at the model's rate.
#include <cmath>

#include "../kind.hpp"

namespace navimpact::stochastic::detail {

namespace {

class RandomWalk final : public KindDef {
 public:
  const KindInfo& info() const override {
    static const KindInfo i{
        ProcessKind::RW, "RW",
        {{"gamma", &Process::gamma, "u/sample", true,
          [](double, double) { return std::make_pair(1e-9, 1e-1); }, "1e-9 .. 0.1 u"}},
        {}, SpectralForm::Density, true};
    return i;
  }

  void convertRate(Process& p, double r) const override {
    // Same continuous random walk K = gamma / sqrt(dt): gamma_new =
    // gamma_old sqrt(old/new). Keeps the dominant gamma^2 tau / 12 =
    // K^2 tau_s / 12 identical; the finite-sample 2 gamma^2/(12 tau) term
    // is not invariant (it is O(dt/tau_s)^2 relative).
    p.gamma /= std::sqrt(r);
  }
  double conversionWvBound(const Process&, double rate_a, double rate_b,
                           double tau_s) const override {
    // In seconds nu^2 = K^2 tau_s / 12 (1 + 2/tau^2), tau = tau_s rate: the
    // excess over the continuous limit, 2/tau^2, is largest at the slower rate.
    const double tau = tau_s * std::min(rate_a, rate_b);
    return 2.0 / (tau * tau);
  }

  double haarWv(const Process& p, double, double tau) const override {
    return p.gamma * p.gamma * (tau * tau + 2.0) / (12.0 * tau);
  }

  void simulateAdd(const Process& p, double, Rng& rng, SimState& st, double* out, std::size_t n) const override {
    // Starts at 0 before the first increment: x_0 = gamma z_0 (cumsum as in R). st.x: the walk.
    double x = st.x;
    for (std::size_t k = 0; k < n; ++k) {
      x += p.gamma * rng.normal();
      out[k] += x;
    }
    st.x = x;
    st.k += n;
  }

  std::optional<SampledArma> sampledArma(const Process& p, double) const override {
    return SampledArma{1.0, 0.0, p.gamma * p.gamma, 0.0};  // starts at 0, as simulated
  }

  int stateCount() const override { return 1; }
  void stateSpace(const Process& p, double rate_hz, StateSpaceBlock& b) const override {
    // x' = w, Qc = K^2 = gamma^2 / dt; P0 = 0.
    const double dt = 1.0 / rate_hz;
    b.Qc(0, 0) = p.gamma * p.gamma / dt;
    b.H(0) = 1.0;
    b.names = {""};
  }

  std::function<double(double)> density(const Process& p, double) const override {
    // Pseudo-spectrum of the integrated white noise: gamma^2 / |1 - e^{-i 2 pi f}|^2
    // = gamma^2 / (4 s); regular after the Haar filter (which differences).
    const double c = p.gamma * p.gamma / 4.0;
    return [c](double s) { return c / s; };
  }

  void addDatasheet(const Process& p, double rate_hz, DatasheetFigures& f) const override {
    // Rate random walk K = gamma / sqrt(dt) [u/sqrt(s)].
    const double dt = 1.0 / rate_hz;
    const double prev = f.random_walk ? *f.random_walk * *f.random_walk * dt : 0.0;
    f.random_walk = std::sqrt((prev + p.gamma * p.gamma) / dt);
  }
};

}  // namespace

const KindDef& kindRW() {
  static const RandomWalk k;
  return k;
}

}  // namespace navimpact::stochastic::detail
