// Power spectral density of a model: each kind's density or line is in
// processes/<name>.cpp; conventions in spectrum.hpp.
#include "navimpact/stochastic/spectrum.hpp"

#include <cmath>
#include <string>

#include "kind.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"

namespace navimpact::stochastic {

SpectralForm spectralForm(ProcessKind k) { return kindInfo(k).spectral; }

Spectrum::Spectrum(const Model& m) : rate_hz_(m.rate_hz) {
  validate(m);
  for (std::size_t i = 0; i < m.terms.size(); ++i) {
    const Process& p = m.terms[i];
    const detail::KindDef& def = detail::kindDef(p.kind);
    switch (def.info().spectral) {
      case SpectralForm::Density: density_.push_back(def.density(p, m.rate_hz)); break;
      case SpectralForm::Line: {
        SpectralLine l = *def.line(p);
        l.term = i;
        lines_.push_back(l);
        break;
      }
      case SpectralForm::Trend: trend_ = true; break;
    }
  }
}

double Spectrum::perSample(double sin2) const {
  double S = 0.0;
  for (const auto& d : density_) S += d(sin2);
  return S;
}

double Spectrum::operator()(double f_hz) const {
  if (!(f_hz > 0.0) || !(f_hz <= 0.5 * rate_hz_))
    throw Error("psd: frequency " + formatNumber(f_hz) + " Hz outside (0, rate/2 = " +
                formatNumber(0.5 * rate_hz_) + " Hz]");
  const double s = std::sin(M_PI * f_hz / rate_hz_);
  return 2.0 / rate_hz_ * perSample(s * s);  // one-sided, per Hz: 2 dt S
}

double psd(const Model& m, double f_hz) { return Spectrum(m)(f_hz); }

std::vector<SpectralLine> lines(const Model& m) { return Spectrum(m).lines(); }

}  // namespace navimpact::stochastic
