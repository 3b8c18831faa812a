/**
 * @file outage.hpp
 * @brief The one GNSS outage of navimpact: its type, its text form
 *        START:DURATION and its validation, used by every command
 *        (replay, study, sweep, diagnose) and by the navigation run; and
 *        the pattern PERIOD:DURATION of outages all along a run.
 *
 * An outage is the half-open interval (start_s, end_s]: GNSS fixes with
 * start_s < t <= end_s are not used (a fix at start_s is the last one used).
 * Times are in seconds in the time base of whoever holds the outage: in
 * configs and on the command line, from the start of the run (the trajectory
 * start of a study or diagnosis, the first IMU sample of a replay); inside a
 * run plan, absolute filter time (shifted()).
 */
#pragma once

#include <string>
#include <vector>

namespace navimpact {

/// A GNSS outage (start_s, end_s] [s].
struct Outage {
  double start_s = 0.0;  ///< last instant with GNSS [s]; >= 0 from the run start
  double end_s = 0.0;    ///< end of the outage [s]; > start_s

  /// From START and DURATION [s]: (start_s, start_s + duration_s].
  static Outage fromStartDuration(double start_s, double duration_s) { return {start_s, start_s + duration_s}; }
  /// Length [s].
  double duration_s() const { return end_s - start_s; }
  /// True if a GNSS fix at @p t [s] falls in the outage (start_s < t <= end_s).
  bool covers(double t) const { return t > start_s && t <= end_s; }
  /// The same outage with @p t0_s added to both ends (run time -> filter time).
  Outage shifted(double t0_s) const { return {t0_s + start_s, t0_s + end_s}; }
};

/// True if any outage covers @p t.
bool inOutage(double t, const std::vector<Outage>& outages);

/// "START:DURATION" as a user writes it (shortest decimal text of each, e.g. "200:60").
std::string outageText(const Outage& o);

/// Parses "START:DURATION" [s] (e.g. "200:60"; spaces around the numbers allowed).
/// @param what how the text is named in a message ("outage", "--outage").
/// @throws navimpact::Error "WHAT 'TEXT': expected START:DURATION in seconds, e.g. 200:60"
///         or "WHAT 'TEXT': START must be in [0, 1e10] s and DURATION in [0.0001, 604800] s"
///         (the ranges of times and durations in limits.hpp).
Outage parseOutage(const std::string& text, const std::string& what = "outage");

/// Outages all along a run: every PERIOD seconds one of DURATION seconds.
struct OutagePattern {
  double period_s = 0.0;    ///< [s], > duration_s
  double duration_s = 0.0;  ///< [s], > 0
};

/// Parses "PERIOD:DURATION" [s] (e.g. "120:30"; spaces around the numbers allowed), PERIOD > DURATION,
/// both durations in limits::kDurationS.
/// @throws navimpact::Error "outages every 'TEXT': expected PERIOD:DURATION in seconds, e.g. 120:30"
///         or "outages every 'TEXT': PERIOD and DURATION must be in [0.0001, 604800] s, PERIOD > DURATION (...)".
OutagePattern parseOutagePattern(const std::string& text);

/**
 * The outages of @p p over [aided_from_s, end_s]: each follows
 * period - duration seconds of GNSS (time to reconverge), the first one too:
 * start_k = aided_from_s + (k + 1) period - duration, end_k = start_k + duration;
 * only outages ending by end_s. Empty when none fits. Times in the base of the arguments.
 */
std::vector<Outage> outagesEvery(const OutagePattern& p, double aided_from_s, double end_s);

/// The one validation of a list of outages in run time [s]: each starts at a
/// finite time >= 0 and lasts a finite time > 0, they are in time order
/// without overlap, and each ends at most 1 microsecond after @p span_s, the
/// length of the run. @p after names the end of the data in the message
/// ("the data (IMU data span 0..260 s)"). Outage i is named @p names[i]
/// where given (the configuration key or flag it came from: "FILE: key
/// 'outages[1]': outage 150:30", "--outage 150:30"), else "WHAT S:D";
/// @p names holds at most one name per outage.
/// @throws navimpact::Error "NAME ends at E s, after AFTER",
///         "NAME: START must be >= 0 s and DURATION > 0 s",
///         "NAME starts before the previous outage ends (outages in time order, no overlap)".
void checkOutages(const std::vector<Outage>& outages, double span_s, const std::string& after,
                  const std::string& what = "outage", const std::vector<std::string>& names = {});

}  // namespace navimpact
