/**
 * @file process_kind.hpp
 * @brief What each process kind is: its name and parameters in the text form,
 *        their units and documented ranges, its spectral form.
 *
 * Every kind is defined in one file, lib/stochastic/src/processes/<name>.cpp,
 * which holds everything specific to it: the text form (name, keys, aliases
 * such as AR1 for GM), validation, exact rate conversion, the theoretical Haar
 * WV, simulation, the state-space form, the power spectral density (or its
 * spectral line) and its contribution to the datasheet figures. The generic
 * functions (parseTerms, validate, convertRate, haarWv, simulate, stateSpace,
 * psd, datasheetFigures) dispatch to it; tests/stochastic/test_process_kinds.cpp
 * runs one property battery for every kind. The list of kinds is
 * process_kinds.def.
 */
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "navimpact/stochastic/process.hpp"

namespace navimpact::stochastic {

/// How a kind shows in the spectrum (see spectrum.hpp).
enum class SpectralForm {
  Density,  ///< a power spectral density (WN, QN, GM; RW as the limit of GM, a pseudo-spectrum)
  Line,     ///< a spectral line at one frequency with a power (SIN)
  Trend,    ///< a deterministic trend, neither density nor line (DR)
};

/// One parameter of a kind in the text form. Units: "u" is the signal's SI
/// unit (rad/s for gyroscopes, m/s^2 for accelerometers).
struct ParamInfo {
  const char* key;          ///< key in the text form, e.g. "sigma", "T"
  double Process::*field;   ///< the member of Process that stores it
  const char* unit;         ///< e.g. "u/sample", "s", "Hz"
  bool positive;            ///< must be a finite number > 0 (else: any finite number)
  /// Documented range over which the kind is supported and tested, for a
  /// record of @p duration_s seconds at @p rate_hz: [lo, hi] of the
  /// magnitude (the property tests draw log-uniformly in it, with a random
  /// sign when !positive).
  std::pair<double, double> (*range)(double rate_hz, double duration_s);
  const char* range_text;   ///< the same range in words
};

/// Another name under which the text form accepts a kind (AR1 for GM).
struct AliasInfo {
  const char* name;                ///< e.g. "AR1"
  std::vector<const char*> keys;   ///< e.g. {"phi", "sigma2"}
};

/// Everything a caller may ask about a kind without calling it.
struct KindInfo {
  ProcessKind kind;
  const char* name;                ///< text-form name, e.g. "GM"
  std::vector<ParamInfo> params;   ///< in the canonical (print) order
  std::vector<AliasInfo> aliases;  ///< other input forms of the same kind
  SpectralForm spectral;
  /// True when stateSpace() reproduces the process exactly (its Haar WV
  /// follows); false when it is an approximation (QN enters as white noise
  /// of the same per-sample variance).
  bool state_space_exact;
};

/// The kind's description. Every ProcessKind has one.
const KindInfo& kindInfo(ProcessKind k);

/// What the kind is, in one line (from process_kinds.def).
const char* kindSummary(ProcessKind k);

/// Every kind, in the canonical order of process_kinds.def.
const std::vector<ProcessKind>& allKinds();

/// The kind named @p name (case-insensitive; aliases included, "AR1" -> GM).
std::optional<ProcessKind> kindFromName(const std::string& name);

/// Documented range of parameter @p i of @p k (see ParamInfo::range).
std::pair<double, double> paramRange(ProcessKind k, std::size_t i, double rate_hz,
                                     double duration_s);

}  // namespace navimpact::stochastic
