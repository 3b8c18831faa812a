// The plan of emulated navigation runs along a trajectory (study, sweep,
// diagnosis' navigation gain), built once.
#include "navimpact/analysis/run_plan.hpp"

#include <algorithm>
#include <cmath>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/emulation/perfect_imu.hpp"

namespace navimpact::analysis {

double runStart(const emulation::SmoothTrajectory& tr, std::optional<double> start_s) {
  return start_s ? std::max(tr.tBegin(), *start_s) : tr.tBegin();
}

std::size_t imuSamples(double t0, double t_end, double rate_hz) {
  const double k = std::floor((t_end - t0) * rate_hz + 1e-9);
  return k > 0.0 ? static_cast<std::size_t>(k) : 0;
}

RunPlan planRuns(const RunPlanOptions& opt) {
  const double rate = opt.imu_rate_hz;
  if (!(rate > 0.0) || !std::isfinite(rate))
    throw Error("run plan: IMU rate must be > 0 Hz, got " + formatNumber(rate));
  RunPlan plan;
  plan.opt = opt;
  plan.rate_hz = rate;

  // Trajectory and its smooth truth; n whole IMU intervals from the start.
  plan.traj = opt.smoothed ? opt.smoothed
                           : std::make_shared<const emulation::SmoothTrajectory>(
                                 emulation::readTrajectoryCsv(opt.trajectory), opt.smoothing);
  const emulation::SmoothTrajectory& tr = *plan.traj;
  plan.t0 = runStart(tr, opt.start_s);
  if (plan.t0 > tr.tEnd())
    throw Error("run plan: the run starts at " + formatNumber(plan.t0) + " s, after the end of the trajectory (" +
                formatNumber(tr.tEnd()) + " s)");
  const std::size_t n = imuSamples(plan.t0, tr.tEnd(), rate);
  plan.t1 = plan.t0 + double(n) / rate;
  const double duration = plan.duration_s();

  // Outages inside the run.
  checkOutages(opt.outages, duration,
               "the end of the trajectory " + (opt.smoothed ? std::string() : opt.trajectory.file + " ") + "(" +
                   formatNumber(duration) + " s)",
               opt.outage_name, opt.outage_names);

  // Perfect IMU.
  plan.perfect = emulation::perfectImu(tr, rate, plan.t0, plan.t1);
  if (plan.perfect.size() != n)
    throw Error("run plan: perfect IMU has " + std::to_string(plan.perfect.size()) + " samples, expected " +
                std::to_string(n));

  // Record epochs (IMU sample indices): record rate over the run, outage rate inside outages.
  std::vector<std::size_t> ks, ends;
  auto stepOf = [rate](double record_hz) {  // 0: no epochs at that rate
    return record_hz > 0.0 ? std::max<std::size_t>(1, std::size_t(std::llround(rate / record_hz))) : 0;
  };
  const std::size_t step_out = stepOf(opt.record_rate_hz), step_in = stepOf(opt.outage_record_rate_hz);
  if (step_out > 0)
    for (std::size_t k = 0; k <= n; k += step_out) ks.push_back(k);
  for (const auto& o : opt.outages) {
    const auto ka = std::size_t(std::llround(o.start_s * rate));
    const auto ke = std::min(n, std::size_t(std::llround(o.end_s * rate)));
    if (step_in > 0)
      for (std::size_t k = ka; k < ke; k += step_in) ks.push_back(k);
    ks.push_back(ke);
    ends.push_back(ke);
  }
  std::sort(ks.begin(), ks.end());
  ks.erase(std::unique(ks.begin(), ks.end()), ks.end());
  for (std::size_t k : ks) {
    const double t = plan.t0 + double(k) / rate;
    plan.truth.t.push_back(t);
    plan.truth.x.push_back(emulation::truthNavState(tr, t));
  }
  for (std::size_t ke : ends)
    plan.outage_end_epoch.push_back(static_cast<std::size_t>(std::lower_bound(ks.begin(), ks.end(), ke) - ks.begin()));
  plan.truth0 = emulation::truthNavState(tr, plan.t0);

  // Filter options shared by every run.
  NavRunOptions& nav = plan.nav;
  nav.ekf = opt.ekf;
  nav.P0_nav = opt.initial_sigma.cwiseAbs2().asDiagonal();
  for (const auto& o : opt.outages) nav.outages.push_back(o.shifted(plan.t0));
  nav.lever_arm_B = opt.gnss.lever_arm_B;
  nav.baro_in_outage = opt.baro_in_outage;
  return plan;
}

EmulatedRun RunPlan::emulate(const std::array<std::vector<double>, 6>& err, std::uint64_t run_seed) const {
  return emulateRun(perfect, err, *traj, t0, t1, opt.gnss, opt.baro, truth0, opt.initial_sigma, run_seed);
}

NavRunInput RunPlan::input(const EmulatedRun& run) const {
  NavRunInput in = run.input(truth);
  if (!opt.use_baro) in.baro = nullptr;
  return in;
}

}  // namespace navimpact::analysis
