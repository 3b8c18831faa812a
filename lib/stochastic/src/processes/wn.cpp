// WN(sigma): white noise, x_k ~ N(0, sigma^2), sigma per sample at the model's rate.
#include <cmath>

#include "../kind.hpp"

namespace navimpact::stochastic::detail {

namespace {

class WhiteNoise final : public KindDef {
 public:
  const KindInfo& info() const override {
    static const KindInfo i{
        ProcessKind::WN, "WN",
        {{"sigma", &Process::sigma, "u/sample", true,
          [](double, double) { return std::make_pair(1e-6, 10.0); }, "1e-6 .. 10 u"}},
        {}, SpectralForm::Density, true};
    return i;
  }

  void convertRate(Process& p, double r) const override {
    // Same white-noise density N = sigma sqrt(dt): sigma_new^2 dt_new =
    // sigma_old^2 dt_old  =>  sigma_new = sigma_old sqrt(new/old). Keeps the
    // WV in seconds, sigma^2/(tau_s rate), identical at every scale.
    p.sigma *= std::sqrt(r);
  }
  double conversionWvBound(const Process&, double, double, double) const override { return 0.0; }

  double haarWv(const Process& p, double, double tau) const override {
    return p.sigma * p.sigma / tau;  // sigma^2/tau
  }

  void simulateAdd(const Process& p, double, Rng& rng, SimState& st, double* out, std::size_t n) const override {
    for (std::size_t k = 0; k < n; ++k) out[k] += p.sigma * rng.normal();
    st.k += n;
  }

  std::optional<SampledArma> sampledArma(const Process& p, double) const override {
    return SampledArma{0.0, 0.0, p.sigma * p.sigma, p.sigma * p.sigma};  // x_k = e_k
  }

  int stateCount() const override { return 0; }
  void stateSpace(const Process& p, double rate_hz, StateSpaceBlock& b) const override {
    const double dt = 1.0 / rate_hz;
    b.white_psd = p.sigma * p.sigma * dt;  // N^2 = sigma^2 dt
  }

  std::function<double(double)> density(const Process& p, double) const override {
    const double s2 = p.sigma * p.sigma;
    return [s2](double) { return s2; };
  }

  void addDatasheet(const Process& p, double rate_hz, DatasheetFigures& f) const override {
    // Noise density N = sigma sqrt(dt) (ARW for gyros, VRW for accs).
    const double prev = f.noise_density ? *f.noise_density * *f.noise_density : 0.0;
    const double dt = 1.0 / rate_hz;
    f.noise_density = std::sqrt(prev + p.sigma * p.sigma * dt);
  }
};

}  // namespace

const KindDef& kindWN() {
  static const WhiteNoise k;
  return k;
}

}  // namespace navimpact::stochastic::detail
