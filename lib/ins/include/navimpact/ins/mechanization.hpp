/**
 * @file mechanization.hpp
 * @brief Strapdown INS mechanization in the local-navigation (NED) frame,
 *        Groves 2013 §5.4-5.5 (precision form with coning and sculling).
 *
 * Usage (emulation / replay):
 * @code
 *   ins::Mechanization ins(initial_state);          // NavState at t0
 *   for (const ins::ImuSample& s : samples) ins.step(s);   // s.t increasing
 *   const ins::NavState& x = ins.state();
 * @endcode
 * The filter (lib/filter) owns a Mechanization, corrects each raw sample by
 * its estimated IMU errors before step(), and writes closed-loop corrections
 * back with setState().
 */
#pragma once

#include <optional>

#include "navimpact/core/earth.hpp"
#include "navimpact/ins/nav_state.hpp"

namespace navimpact::ins {

struct MechanizationOptions {
  /// Coning and sculling corrections using the previous intervals' increments
  /// (two-sample: Groves 5.97-5.98 / Savage 1998; three-sample once two
  /// previous intervals are known). Off = single-sample form.
  bool coning_sculling = true;
};

/**
 * One mechanization step from @p prev over the sample @p cur.
 * @param[in] prev       state at cur.t - cur.dt.
 * @param[in] cur        (already error-corrected) increments of this interval.
 * @param[in] last       increments of the previous interval (for the
 *                       two-sample corrections); nullptr = none (first step).
 * @param[in] opt        options.
 * @return the state at cur.t.
 */
NavState mechanize(const NavState& prev, const ImuSample& cur, const ImuSample* last,
                   const MechanizationOptions& opt = {});

/**
 * As above, with the increments of the two previous intervals: three-sample
 * coning and sculling (exact for rates quadratic in time over the three
 * intervals; falls back to the two-sample form when @p last2 is nullptr).
 * @param[in] prev   state at cur.t - cur.dt.
 * @param[in] cur    (already error-corrected) increments of this interval.
 * @param[in] last   increments of the interval before (nullptr = none).
 * @param[in] last2  increments of the interval before @p last (nullptr = none);
 *                   all three intervals of equal length.
 * @param[in] opt    options.
 * @param[in,out] gravity  local gravity cache (earth::LocalGravity, within
 *                   1e-9 m/s^2 of GeographicLib); nullptr = evaluate
 *                   earth::gravity_N() directly (twice per step).
 * @return the state at cur.t.
 */
NavState mechanize(const NavState& prev, const ImuSample& cur, const ImuSample* last,
                   const ImuSample* last2, const MechanizationOptions& opt = {},
                   earth::LocalGravity* gravity = nullptr);

/**
 * The same step with the latitude terms of prev.lat given (@p L0, equal to
 * earth::LatitudeTerms(prev.lat)); the terms of the new latitude are stored in
 * @p L1_out when it is not null (the next step's L0). Same result, bit for bit.
 */
NavState mechanize(const NavState& prev, const ImuSample& cur, const ImuSample* last,
                   const ImuSample* last2, const MechanizationOptions& opt,
                   earth::LocalGravity* gravity, const earth::LatitudeTerms& L0,
                   std::optional<earth::LatitudeTerms>* L1_out);

/// Stateful wrapper: keeps the current state and the previous increments.
class Mechanization {
 public:
  Mechanization() = default;
  /// @param[in] initial  state at the start time initial.t.
  explicit Mechanization(const NavState& initial, const MechanizationOptions& opt = {})
      : x_(initial), opt_(opt) {}

  /// Integrate one interval; @p s.dt > 0, s.t = state().t + s.dt (not checked).
  void step(const ImuSample& s);
  const NavState& state() const { return x_; }
  /// Overwrite the state (closed-loop correction); the increment history is kept.
  void setState(const NavState& x) { x_ = x; }
  /// Provide the increments that preceded state().t (older first), so that the
  /// first step() is a regular multi-sample step. @p last2 may be nullptr.
  void setHistory(const ImuSample& last, const ImuSample* last2 = nullptr) {
    last_ = last;
    has_last_ = true;
    if (last2 != nullptr) last2_ = *last2;
    has_last2_ = last2 != nullptr;
  }
  /// Forget the previous increments (after a data gap).
  void resetHistory() { has_last_ = has_last2_ = false; }
  const MechanizationOptions& options() const { return opt_; }

 private:
  NavState x_;
  MechanizationOptions opt_;
  earth::LocalGravity gravity_;
  std::optional<earth::LatitudeTerms> lat_terms_;  ///< of x_.lat when it was computed  ///< GeographicLib normal gravity, linearised per 10 m / 640 m box
  ImuSample last_, last2_;
  bool has_last_ = false, has_last2_ = false;
};

}  // namespace navimpact::ins
