// QN(Q): quantization noise as in the R package gmwm, x_k = sqrt(12) Q (u_k - u_{k-1}),
// u ~ U(0,1) (the first difference of a uniform white noise of variance Q^2).
#include <cmath>

#include "../kind.hpp"

namespace navimpact::stochastic::detail {

namespace {

class QuantizationNoise final : public KindDef {
 public:
  const KindInfo& info() const override {
    static const KindInfo i{
        ProcessKind::QN, "QN",
        {{"Q", &Process::Q, "u", true,
          [](double, double) { return std::make_pair(1e-6, 10.0); }, "1e-6 .. 10 u"}},
        {}, SpectralForm::Density,
        false};  // the filter takes it as white noise of the same per-sample variance
    return i;
  }

  void convertRate(Process& p, double r) const override {
    // Same quantization Q_c = Q dt (unit*s): Q_new = Q_old new/old. Keeps
    // 6 Q^2 / tau^2 = 6 Q^2 / (tau_s rate)^2 identical.
    p.Q *= r;
  }
  double conversionWvBound(const Process&, double, double, double) const override { return 0.0; }

  double haarWv(const Process& p, double, double tau) const override {
    return 6.0 * p.Q * p.Q / (tau * tau);  // 6 Q^2/tau^2 (telescoping Haar sum)
  }

  void simulateAdd(const Process& p, double, Rng& rng, SimState& st, double* out, std::size_t n) const override {
    // R gmwm gen_qn: sqrt(12 Q^2) (u_k - u_{k-1}), u ~ U(0,1); var = 2 Q^2.
    // st.x: the last uniform drawn.
    const double c = std::sqrt(12.0) * p.Q;
    if (st.k == 0) st.x = rng.uniform();
    double prev = st.x;
    for (std::size_t k = 0; k < n; ++k) {
      const double u = rng.uniform();
      out[k] += c * (u - prev);
      prev = u;
    }
    st.x = prev;
    st.k += n;
  }

  std::optional<SampledArma> sampledArma(const Process& p, double) const override {
    // x_k = e_k - e_{k-1}, e_k = sqrt(12) Q u_k of variance Q^2 (as simulated).
    return SampledArma{0.0, 1.0, p.Q * p.Q, p.Q * p.Q};
  }

  int stateCount() const override { return 0; }
  void stateSpace(const Process& p, double rate_hz, StateSpaceBlock& b) const override {
    const double dt = 1.0 / rate_hz;
    b.white_psd = 2.0 * p.Q * p.Q * dt;  // per-sample variance 2 Q^2 as white (conservative)
  }

  std::function<double(double)> density(const Process& p, double) const override {
    // X_k = sqrt(12) Q (U_k - U_{k-1}), Var U = 1/12: |1 - e^{-i 2 pi f}|^2 Q^2 = 4 Q^2 s.
    const double c = 4.0 * p.Q * p.Q;
    return [c](double s) { return c * s; };
  }

  void addDatasheet(const Process& p, double rate_hz, DatasheetFigures& f) const override {
    // Quantization Q_c = Q dt [u s] (IEEE 952's Q, with the R package's Q per sample).
    const double dt = 1.0 / rate_hz;
    const double prev = f.quantization ? *f.quantization / dt : 0.0;
    f.quantization = std::sqrt(prev * prev + p.Q * p.Q) * dt;
  }
};

}  // namespace

const KindDef& kindQN() {
  static const QuantizationNoise k;
  return k;
}

}  // namespace navimpact::stochastic::detail
