// The interface every process kind implements (internal to lib/stochastic).
// One kind = one file in src/processes/ defining a KindDef and
// `const KindDef& kind<NAME>()`; process_kinds.def lists the kinds; the
// public functions (model_text, process, theoretical_wv, simulate,
// state_space, spectrum, datasheet) dispatch through kindDef().
#pragma once

#include <cstddef>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>

#include "navimpact/core/format.hpp"
#include "navimpact/stochastic/block_likelihood.hpp"
#include "navimpact/stochastic/datasheet.hpp"
#include "navimpact/stochastic/process_kind.hpp"
#include "navimpact/stochastic/spectrum.hpp"
#include "navimpact/stochastic/state_space.hpp"
#include "rng.hpp"

namespace navimpact::stochastic::detail {

/// A value of an alias form that cannot be converted: which key (or -1 for
/// the name), what was expected, what was found (for the parser's message).
struct AliasValueError {
  int key = -1;
  std::string expected, found;
};

/// What a process carries from one block of simulated samples to the next.
struct SimState {
  std::size_t k = 0;             ///< samples simulated so far
  double x = 0.0, y = 0.0, z = 0.0;  ///< the kind's state (its own meaning per kind)
};

class KindDef {
 public:
  virtual ~KindDef() = default;

  virtual const KindInfo& info() const = 0;

  /// Build the process from an alias form (info().aliases[alias]) with its
  /// values in the alias' key order. @throws AliasValueError.
  virtual Process fromAlias(std::size_t alias, const double* values, double rate_hz) const {
    throw AliasValueError{-1, "a process name", "an alias without conversion"};
  }

  /// Checks beyond each parameter's finiteness/positivity (e.g. SIN below
  /// Nyquist): empty if fine, else "KEY must ..." for the error message.
  virtual std::string check(const Process& p, double rate_hz) const { return {}; }

  /// Convert the parameters in place to a rate @p r times the model's
  /// (r = new/old) for the same continuous-time process.
  virtual void convertRate(Process& p, double r) const = 0;

  /// Documented accuracy of convertRate for the Haar WV in seconds: a bound
  /// on |nu2_new - nu2_old| / nu2_old at the scale of @p tau_s seconds
  /// between the rates @p rate_a and @p rate_b (0 where the conversion
  /// keeps the WV exactly).
  virtual double conversionWvBound(const Process& p, double rate_a, double rate_b,
                                   double tau_s) const = 0;

  /// Haar WV at scale @p tau samples (>= 2, checked by the caller).
  virtual double haarWv(const Process& p, double rate_hz, double tau) const = 0;

  /// Add the next @p n samples of the process to @p out, drawing from @p rng.
  /// @p st carries the process between calls (st.k: samples given so far; a
  /// kind's start draws happen when st.k == 0), so consecutive calls give the
  /// samples of one call over their total length, bit for bit.
  virtual void simulateAdd(const Process& p, double rate_hz, Rng& rng, SimState& st, double* out,
                           std::size_t n) const = 0;

  /// Fill the state-space block (F, Qc, H, P0, white_psd, state labels);
  /// @p b comes sized by stateCount().
  virtual int stateCount() const = 0;
  virtual void stateSpace(const Process& p, double rate_hz, StateSpaceBlock& b) const = 0;

  /// Density kinds: the two-sided density per sample as a function of
  /// s = sin^2(pi f dt), constants computed once (see spectrum.hpp).
  virtual std::function<double(double)> density(const Process& p, double rate_hz) const {
    return {};
  }
  /// Line kinds: the line.
  virtual std::optional<SpectralLine> line(const Process& p) const { return std::nullopt; }

  /// Random kinds: the exact per-sample form x_k = z_k - mu z_{k-1},
  /// z_k = phi z_{k-1} + e_k (see block_likelihood.hpp); deterministic kinds
  /// (a trend, a line) have none.
  virtual std::optional<SampledArma> sampledArma(const Process& p, double rate_hz) const {
    return std::nullopt;
  }

  /// Add the kind's contribution to the datasheet figures (continuous-time
  /// figures of independent terms add in variance, drift rates add).
  virtual void addDatasheet(const Process& p, double rate_hz, DatasheetFigures& f) const {}
};

/// @throws navimpact::Error unless tau >= 2 samples (the scales of the Haar WV).
void checkTau(double tau);

/// The definition of a kind.
const KindDef& kindDef(ProcessKind k);

/// @p a equals @p b ignoring ASCII case (process names and keys).
bool iequals(const std::string& a, const char* b);

}  // namespace navimpact::stochastic::detail
