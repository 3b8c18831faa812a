// SIN(amp, freq): sinusoid x_k = amp sin(2 pi freq k dt + theta) with a random
// phase theta ~ U(0, 2 pi); amp in the signal's unit, freq in Hz below Nyquist.
#include <algorithm>
#include <cmath>

#include "../kind.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"

namespace navimpact::stochastic::detail {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 6.283185307179586476925;

class Sinusoid final : public KindDef {
 public:
  const KindInfo& info() const override {
    static const KindInfo i{
        ProcessKind::SIN, "SIN",
        {{"amp", &Process::amp, "u", true,
          [](double, double) { return std::make_pair(1e-6, 10.0); }, "1e-6 .. 10 u"},
         {"freq", &Process::freq_hz, "Hz", true,
          [](double rate, double dur) { return std::make_pair(5.0 / dur, 0.45 * rate); },
          "5/duration .. 0.45 rate Hz (must be below rate/2)"}},
        {}, SpectralForm::Line, true};
    return i;
  }

  std::string check(const Process& p, double rate_hz) const override {
    if (!(p.freq_hz < 0.5 * rate_hz))
      return "freq must be below the Nyquist frequency rate_hz/2 = " + formatNumber(0.5 * rate_hz) +
             " Hz";
    return {};
  }

  void convertRate(Process&, double) const override {
    // The same sinusoid (amplitude in the signal's unit, frequency in Hz).
  }
  double conversionWvBound(const Process& p, double rate_a, double rate_b,
                           double tau_s) const override {
    // nu^2 = (A^2/2) sin^4(pi f tau_s / 2) / (n^2 sin^2(pi f dt)) with
    // n^2 sin^2(pi f dt) = (pi f tau_s / 2)^2 sinc^2(x), x = pi f dt: the WV in
    // seconds scales as 1/sinc^2(x), which lies in [1, 1/sinc^2(x_slow)] (sinc
    // decreases on [0, pi/2]; x_slow at the slower rate).
    const double x = kPi * p.freq_hz / std::min(rate_a, rate_b);
    const double sinc = std::sin(x) / x;
    return 1.0 / (sinc * sinc) - 1.0 + 1e-14;
  }

  double haarWv(const Process& p, double rate_hz, double tau) const override {
    // Random-phase sinusoid A sin(w k + theta), w = 2 pi f / rate [rad/sample].
    // The mean of n consecutive samples is A D sin(w c + theta) with
    // D = sin(n w/2) / (n sin(w/2)); two adjacent means differ by a phase
    // n w, so W = A D sin(n w/2) cos(.), and averaging cos^2 over the phase:
    //   nu^2 = (A^2/2) sin^4(n w/2) / (n^2 sin^2(w/2)).
    if (!(rate_hz > 0.0)) throw Error("SIN wavelet variance: needs rate_hz > 0");
    const double w = 2.0 * kPi * p.freq_hz / rate_hz;
    const double n = 0.5 * tau;
    const double s = std::sin(0.5 * n * w);
    const double sw = std::sin(0.5 * w);
    return 0.5 * p.amp * p.amp * s * s * s * s / (n * n * sw * sw);
  }

  void simulateAdd(const Process& p, double rate_hz, Rng& rng, SimState& st, double* out,
                   std::size_t n) const override {
    // amp sin(w k + theta), theta ~ U(0, 2 pi). Rotation recurrence,
    // re-anchored exactly at every 1024th sample so rounding cannot accumulate.
    // st.z: theta; st.x, st.y: sin and cos of the next sample's angle.
    const double w = kTwoPi * p.freq_hz / rate_hz;
    if (st.k == 0) st.z = kTwoPi * rng.uniform();
    const double theta = st.z;
    const double cw = std::cos(w), sw = std::sin(w);
    double s = st.x, c = st.y;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t k = st.k + i;
      if (k % 1024 == 0) {
        const double a0 = w * static_cast<double>(k) + theta;
        s = std::sin(a0);
        c = std::cos(a0);
      }
      out[i] += p.amp * s;
      const double s1 = s * cw + c * sw;
      c = c * cw - s * sw;
      s = s1;
    }
    st.x = s;
    st.y = c;
    st.k += n;
  }

  int stateCount() const override { return 2; }
  void stateSpace(const Process& p, double, StateSpaceBlock& b) const override {
    // Oscillator [a sin, a cos] at w = 2 pi f: F = [0 w; -w 0], Qc = 0,
    // P0 = diag(amp^2/2, amp^2/2) (random phase), H = [1 0].
    const double w = kTwoPi * p.freq_hz;
    b.F(0, 1) = w;
    b.F(1, 0) = -w;
    b.H(0) = 1.0;
    b.P0(0, 0) = b.P0(1, 1) = 0.5 * p.amp * p.amp;
    const std::string f = "(f=" + formatNumber(p.freq_hz, 4) + "Hz)";
    b.names = {f + ".a", f + ".b"};
  }

  std::optional<SpectralLine> line(const Process& p) const override {
    return SpectralLine{p.freq_hz, 0.5 * p.amp * p.amp, 0};  // power = variance amp^2/2
  }
};

}  // namespace

const KindDef& kindSIN() {
  static const Sinusoid k;
  return k;
}

}  // namespace navimpact::stochastic::detail
