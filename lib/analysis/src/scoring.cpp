// A navigation run scored against a reference (see scoring.hpp).
#include "navimpact/analysis/scoring.hpp"

#include <Eigen/Cholesky>
#include <boost/math/distributions/chi_squared.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/text_io.hpp"

namespace navimpact::analysis {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double chi2q(double dof, double p) { return boost::math::quantile(boost::math::chi_squared(dof), p); }

}  // namespace

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const double h = q * double(v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (h - double(lo)) * (v[hi] - v[lo]);
}

void RunScorer::add(const NavEpoch& e, const std::vector<Outage>& outages) {
  // Errors along the run over the GNSS-aided time.
  if (e.t < aided_from_ - 1e-9) return;
  for (const auto& o : outages)
    if (e.t > o.start_s && e.t <= o.end_s + 1e-9) return;
  ++aided_epochs_;
  sh_ += e.err.head<2>().squaredNorm();
  sv_ += e.err[2] * e.err[2];
  svel_ += e.err.segment<3>(3).squaredNorm();
  satt_ += e.err.segment<3>(6).cwiseAbs2();
}

RunScore scoreRun(const NavRunResult& run, double t_zero, double aided_from, const ReferenceInfo& ref) {
  if (!run.has_truth) throw Error("scoring: the run has no reference");
  RunScorer scorer(aided_from);
  std::vector<Outage> windows;
  for (const auto& o : run.outages) windows.push_back(o.window);
  for (const NavEpoch& e : run.epochs) scorer.add(e, windows);
  // each outage's end epoch and drifts from the epochs
  NavRunResult ends;
  ends.has_truth = true;
  ends.outages = run.outages;
  for (auto& o : ends.outages) {
    if (o.end_epoch < 0) continue;
    o.end = run.epochs.at(static_cast<std::size_t>(o.end_epoch));
    o.max_drift_h = o.max_drift_v = 0.0;
    for (const NavEpoch& k : run.epochs) {
      if (k.t <= o.window.start_s || k.t > o.window.end_s + 1e-9) continue;
      o.max_drift_h = std::max(o.max_drift_h, k.err.head<2>().norm());
      o.max_drift_v = std::max(o.max_drift_v, std::abs(k.err[2]));
    }
  }
  return scorer.finish(ends, t_zero, ref);
}

RunScore RunScorer::finish(const NavRunResult& run, double t_zero, const ReferenceInfo& ref) const {
  if (!run.has_truth) throw Error("scoring: the run has no reference");
  if (!(ref.sigma_h_m >= 0.0) || !(ref.sigma_v_m >= 0.0) || !std::isfinite(ref.sigma_h_m) ||
      !std::isfinite(ref.sigma_v_m))
    throw Error("scoring: reference sigmas must be finite and >= 0");
  RunScore s;
  s.reference = ref;
  const Eigen::Vector3d R_ref(ref.sigma_h_m * ref.sigma_h_m, ref.sigma_h_m * ref.sigma_h_m,
                              ref.sigma_v_m * ref.sigma_v_m);
  s.aided_epochs = aided_epochs_;
  const double n = double(std::max<std::size_t>(s.aided_epochs, 1));
  s.horizontal_rms_m = s.aided_epochs ? std::sqrt(sh_ / n) : kNaN;
  s.vertical_rms_m = s.aided_epochs ? std::sqrt(sv_ / n) : kNaN;
  s.velocity_rms_mps = s.aided_epochs && ref.has_velocity ? std::sqrt(svel_ / n) : kNaN;
  s.attitude_rms_rad = s.aided_epochs && ref.has_attitude ? Eigen::Vector3d((satt_ / n).cwiseSqrt())
                                                           : Eigen::Vector3d::Constant(kNaN);
  // Per outage, at its end.
  OutageDistribution& d = s.distribution;
  d.nees_band_lo = chi2q(3.0, 0.025);
  d.nees_band_hi = chi2q(3.0, 0.975);
  std::vector<double> eh, ev, z;
  double nees_sum = 0.0;
  for (std::size_t i = 0; i < run.outages.size(); ++i) {
    const OutageSummary& o = run.outages[i];
    if (o.end_epoch < 0) {
      s.unscored.push_back(i);
      continue;
    }
    const NavEpoch& e = o.end;
    OutageScore q;
    q.start_s = o.window.start_s - t_zero;
    q.duration_s = o.window.end_s - o.window.start_s;
    q.end_s = e.t - t_zero;
    q.err_N = e.err.head<3>();
    q.sigma_N = e.P_pos.diagonal().cwiseMax(0.0).cwiseSqrt();
    q.horizontal_error_m = q.err_N.head<2>().norm();
    q.vertical_error_m = std::abs(q.err_N[2]);
    q.horizontal_sigma_m = std::sqrt(std::max(0.0, e.P_pos(0, 0) + e.P_pos(1, 1)));
    q.vertical_sigma_m = q.sigma_N[2];
    q.max_drift_h_m = o.max_drift_h;
    q.max_drift_v_m = o.max_drift_v;
    const Eigen::Matrix3d S = e.P_pos + Eigen::Matrix3d(R_ref.asDiagonal());
    Eigen::LLT<Eigen::Matrix3d> llt(S);
    q.nees = llt.info() == Eigen::Success ? q.err_N.dot(llt.solve(q.err_N)) : kNaN;
    q.nees_in_band = q.nees >= d.nees_band_lo && q.nees <= d.nees_band_hi;
    eh.push_back(q.horizontal_error_m);
    ev.push_back(q.vertical_error_m);
    for (int a = 0; a < 3; ++a) z.push_back(std::abs(q.err_N[a]) / std::sqrt(S(a, a)));
    nees_sum += q.nees;
    d.nees_in_band += q.nees_in_band ? 1 : 0;
    s.outages.push_back(q);
  }

  // Distribution over the outages.
  d.count = s.outages.size();
  d.coverage_expected = {std::erf(1.0 / std::sqrt(2.0)), std::erf(2.0 / std::sqrt(2.0)),
                         std::erf(3.0 / std::sqrt(2.0))};
  if (d.count == 0) {
    d.median_h_m = d.p95_h_m = d.median_v_m = d.p95_v_m = d.mean_nees = kNaN;
    d.coverage = {kNaN, kNaN, kNaN};
    d.mean_nees_lo = d.mean_nees_hi = kNaN;
    return s;
  }
  d.median_h_m = percentile(eh, 0.5);
  d.p95_h_m = percentile(eh, 0.95);
  d.median_v_m = percentile(ev, 0.5);
  d.p95_v_m = percentile(ev, 0.95);
  for (int k = 0; k < 3; ++k)
    d.coverage[k] = double(std::count_if(z.begin(), z.end(), [&](double x) { return x <= k + 1.0; })) / z.size();
  const double K = double(d.count);
  d.mean_nees = nees_sum / K;
  d.mean_nees_lo = chi2q(3.0 * K, 0.025) / K;
  d.mean_nees_hi = chi2q(3.0 * K, 0.975) / K;
  return s;
}

}  // namespace navimpact::analysis
