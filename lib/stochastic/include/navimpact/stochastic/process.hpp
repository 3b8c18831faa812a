/**
 * @file process.hpp
 * @brief Latent stochastic processes of IMU errors and their composite sum.
 *
 * Parameter convention (stated once, never mixed; see README "Conventions"):
 *  - WN sigma, QN Q, RW gamma and DR omega are **per sample** at the model's
 *    rate_hz (the paper's Table 1 unit ".../sample"), in the signal's SI unit;
 *  - GM sigma is the **stationary** standard deviation, T the correlation
 *    time in seconds; phi = exp(-dt/T), dt = 1/rate_hz;
 *  - SIN amplitude is in the signal's unit, freq_hz in Hz.
 * AR1(phi, sigma2) of the R package gmwm (sigma2 = innovation variance) is
 * accepted on input and stored as the equivalent GM.
 */
#pragma once

#include <string>
#include <vector>

namespace navimpact::stochastic {

/// The process kinds (process_kinds.def lists them with what each one is;
/// process_kind.hpp describes each kind: parameters, units, ranges).
enum class ProcessKind {
#define NAVIMPACT_PROCESS_KIND(NAME, DOC) NAME,
#include "navimpact/stochastic/process_kinds.def"
};

/// Short name as used in the text form ("WN", "QN", "RW", "DR", "GM", "SIN").
const char* kindName(ProcessKind k);

/// One latent process with its parameters (only those of its kind are used).
struct Process {
  ProcessKind kind = ProcessKind::WN;
  double sigma = 0.0;    ///< WN: per-sample std; GM: stationary std  [unit]
  double Q = 0.0;        ///< QN: quantization parameter (R's sqrt(Q2)) [unit]
  double gamma = 0.0;    ///< RW: per-sample increment std [unit]
  double omega = 0.0;    ///< DR: slope per sample [unit/sample]
  double T = 0.0;        ///< GM: correlation time [s], > 0
  double amp = 0.0;      ///< SIN: amplitude [unit]
  double freq_hz = 0.0;  ///< SIN: frequency [Hz], 0 < f < rate/2

  static Process wn(double sigma);
  static Process qn(double Q);
  static Process rw(double gamma);
  static Process dr(double omega);
  static Process gm(double sigma, double T);
  static Process sin(double amp, double freq_hz);
  /// From the R package's AR1 form at @p rate_hz: T = -dt/ln(phi), sigma = sqrt(sigma2/(1-phi^2)).
  static Process ar1(double phi, double sigma2_innov, double rate_hz);

  bool operator==(const Process& o) const;
};

/// A composite model: the sum of independent processes, at a sampling rate.
struct Model {
  double rate_hz = 0.0;          ///< rate the per-sample parameters refer to [Hz]
  std::vector<Process> terms;    ///< empty = no error ("none")

  bool empty() const { return terms.empty(); }
  /// Number of terms of a kind.
  int count(ProcessKind k) const;
  /// The kinds of the terms in order (formatStructure() prints it as "WN+GM+DR").
  std::vector<ProcessKind> structure() const;
};

/**
 * Exact conversion of a model to another sampling rate, for the same
 * continuous-time process: WN sigma scales by sqrt(new/old) (same noise
 * density), QN Q by new/old... see the implementation comments; GM keeps
 * sigma and T; RW gamma by sqrt(old/new); DR omega by old/new; SIN unchanged.
 */
Model convertRate(const Model& m, double new_rate_hz);

/**
 * Documented accuracy of convertRate() for one term: a bound on the relative
 * change of its Haar WV in seconds, at the scale of @p tau_s seconds, between
 * the rates @p rate_a_hz and @p rate_b_hz. 0 where the conversion keeps it
 * exactly (WN, QN, DR); otherwise the excess of the sampled WV over its
 * continuous-time limit at the slower rate: RW 2/tau^2, GM ~ 1/(2 n^2) +
 * (dt/T)^2/12 (tau = 2n samples; evaluated exactly), SIN 1/sinc^2(pi f dt) - 1.
 */
double conversionWvBound(const Process& p, double rate_a_hz, double rate_b_hz, double tau_s);

/**
 * Validate parameters (finite, sigma/Q/gamma/T/amp > 0, DR omega finite,
 * SIN 0 < freq < rate/2). @throws navimpact::Error naming the term.
 */
void validate(const Model& m);

}  // namespace navimpact::stochastic
