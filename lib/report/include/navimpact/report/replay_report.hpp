/**
 * @file replay_report.hpp
 * @brief What `navimpact replay` writes: solution.csv, summary.json and the
 *        figures in the style of Khaghani et al. (2019) Figures 8 and 9
 *        (error and +-1 sigma envelope, outage shaded), from an
 *        analysis::ReplayResult (data only).
 */
#pragma once

#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "navimpact/analysis/replay.hpp"
#include "navimpact/core/output.hpp"

namespace navimpact::report {

/**
 * The replay's outputs written while it runs (analysis::runReplay with an
 * observer), in memory bounded by the number of outages, not of epochs:
 * solution.csv row by row into the staging folder; summary.json from running
 * sums (per-outage maxima and mean NEES, overall RMS); the figures from at
 * most kMaxFigurePoints epochs (a longer run draws every 2^k-th epoch, the
 * last one included, and the title says so; each of the first 12 outages'
 * zoomed figures then keeps its own epochs, at most 8000). A run of at most
 * 40,000 epochs gives the same files as writing from the whole result.
 */
class ReplayWriter : public analysis::ReplayObserver {
 public:
  /// Stage solution.csv in @p out now (summary, timing and figures at finish()).
  explicit ReplayWriter(OutputSet* out);
  /// solution.csv rows into @p csv only (solutionCsv()).
  explicit ReplayWriter(std::ostream& csv);
  ~ReplayWriter() override;
  void begin(const analysis::ReplayResult& r) override;
  void epoch(const analysis::ReplayResult& r, const analysis::NavEpoch& e, const ins::NavState* truth,
             const std::vector<Outage>& windows) override;
  /// begin() and every epoch of a result that kept them (runReplay without observer).
  void feed(const analysis::ReplayResult& r);
  /// summary.json text (after the last epoch).
  std::string summary(const analysis::ReplayResult& r) const;
  /// Close solution.csv; stage summary.json, timing.json and the figures (the caller commits).
  void finish(const analysis::ReplayResult& r);

  struct State;

 private:
  OutputSet* out_ = nullptr;
  std::unique_ptr<State> st_;
};

/// solution.csv text (one row per recorded epoch; units in the header).
std::string solutionCsv(const analysis::ReplayResult& r);

/// summary.json text.
std::string summaryJson(const analysis::ReplayResult& r);

/// Notices, what was replayed, and per outage the error (or predicted sigma) at its end.
std::string replaySummary(const analysis::ReplayResult& r);

/// Stage solution.csv, summary.json, errors_full.png, errors_outage_K.png (the first 12
/// outages), trajectory.png and, when scored, outage_end_error.png in @p out; the caller commits.
void writeReplayOutputs(const analysis::ReplayResult& r, OutputSet& out);

}  // namespace navimpact::report
