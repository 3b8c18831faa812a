/**
 * @file perfect_imu.hpp
 * @brief Error-free IMU increments generated from a smooth trajectory, in the
 *        input convention of lib/ins (ins::ImuSample: increments over (t-dt, t]).
 */
#pragma once

#include <vector>

#include "navimpact/emulation/trajectory.hpp"
#include "navimpact/ins/nav_state.hpp"

namespace navimpact::emulation {

/**
 * Perfect IMU samples at @p rate_hz over [tr.tBegin(), tr.tEnd()] (or the sub-span
 * [t_start, t_end]): sample k covers (t_start + (k-1)/rate, t_start + k/rate], k = 1..n,
 * with exact increments (SmoothTrajectory::increments). Times are computed as
 * t_start + k / rate (no accumulation of rounding).
 * @param[in] tr       smooth truth.
 * @param[in] rate_hz  IMU rate [Hz], > 0 (any value: 200 Hz from a 100 Hz trajectory is normal).
 * @param[in] t_start  first time [s] (default tBegin; clamped into the span).
 * @param[in] t_end    last time [s] (default tEnd).
 * @throws navimpact::Error when the span holds no whole interval.
 */
std::vector<ins::ImuSample> perfectImu(const SmoothTrajectory& tr, double rate_hz,
                                       double t_start = -1e300, double t_end = 1e300);

/**
 * Samples k0 .. k1-1 of perfectImu(tr, rate_hz, t_first) (the same values; t_first
 * already clamped into the span, k1 at most its sample count), into @p out
 * (cleared first): the perfect IMU of a long run block by block.
 */
void perfectImuBlock(const SmoothTrajectory& tr, double rate_hz, double t_first, std::size_t k0, std::size_t k1,
                     std::vector<ins::ImuSample>& out);

/// Number of samples perfectImu gives over [t_first, t_last] at @p rate_hz.
std::size_t perfectImuCount(double rate_hz, double t_first, double t_last);

/// The true navigation state (lib/ins type) at time @p t.
ins::NavState truthNavState(const SmoothTrajectory& tr, double t);

}  // namespace navimpact::emulation
