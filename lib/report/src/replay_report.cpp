// Outputs of navimpact replay: solution.csv, summary.json and the error figures.
#include "navimpact/report/replay_report.hpp"

#include <yaml-cpp/yaml.h>

#include <nlohmann/json.hpp>

#include <array>
#include <cstdio>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "navimpact/core/format.hpp"
#include "navimpact/plot/figure.hpp"

namespace navimpact::report {

using namespace analysis;

namespace {

constexpr double kDeg = M_PI / 180.0;

/// Roll, pitch, yaw [rad] errors of est w.r.t. truth (yaw wrapped).
Eigen::Vector3d eulerError(const ins::NavState& est, const ins::NavState& truth) {
  Eigen::Vector3d d = est.rollPitchYaw() - truth.rollPitchYaw();
  for (int k = 0; k < 3; ++k) d[k] = ins::wrapAngle(d[k]);
  return d;
}

/// 1-sigma of roll, pitch, yaw from the psi sigmas (J diag(s^2) J', cross-covariances ignored).
Eigen::Vector3d eulerSigma(const ins::NavState& truth, const Eigen::Vector3d& sigPsi) {
  const Eigen::Matrix3d C = truth.C_BtoN();
  const Eigen::Vector3d e0 = ins::rollPitchYaw(C);
  const double eps = 1e-6;
  Eigen::Matrix3d J;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    p[i] = eps;
    Eigen::Vector3d d = ins::rollPitchYaw((Eigen::Matrix3d::Identity() + ins::skew(p)) * C) - e0;
    for (int k = 0; k < 3; ++k) d[k] = ins::wrapAngle(d[k]);
    J.col(i) = d / eps;
  }
  const Eigen::Matrix3d S = J * sigPsi.cwiseAbs2().asDiagonal() * J.transpose();
  return S.diagonal().cwiseMax(0.0).cwiseSqrt();
}

void writeReplayFigures(const ReplayResult& r, OutputSet& out) {
  const auto& ep = r.run.epochs;
  const std::size_t n = ep.size();
  std::vector<double> t(n);
  std::array<std::vector<double>, 9> err, sig;
  for (auto& v : err) v.resize(n);
  for (auto& v : sig) v.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    t[k] = ep[k].t - r.t_zero;
    const bool truth = r.run.has_truth;
    for (int i = 0; i < 6; ++i) {
      err[i][k] = ep[k].err[i];
      sig[i][k] = ep[k].sigma[i];
    }
    const Eigen::Vector3d ee =
        truth ? Eigen::Vector3d(eulerError(r.estimate[k], r.truth[k]) / kDeg) : Eigen::Vector3d::Zero();
    const Eigen::Vector3d se = eulerSigma(truth ? r.truth[k] : r.estimate[k], ep[k].sigma.segment<3>(6)) / kDeg;
    for (int i = 0; i < 3; ++i) {
      err[6 + i][k] = ee[i];
      sig[6 + i][k] = se[i];
    }
  }
  const char* names[9] = {"north", "east", "down", "north", "east", "down", "roll", "pitch", "yaw"};
  const char* units[3] = {"position error [m]", "velocity error [m/s]", "attitude error [deg]"};
  auto figure = [&](double x0, double x1, const std::string& title) {
    plot::Figure fig;
    fig.width = 1800;
    fig.height = 1200;
    fig.rows = 3;
    fig.cols = 3;
    fig.title = title;
    for (int i = 0; i < 9; ++i) {
      plot::Axes ax;
      ax.title = names[i];
      if (i % 3 == 0) ax.ylabel = units[i / 3];
      if (i >= 6) ax.xlabel = "time [s]";
      ax.xlim = std::make_pair(x0, x1);
      for (const auto& o : r.cfg.outages)
        ax.spans.push_back({"GNSS outage", o.start_s, o.end_s, {128, 128, 128}, 0.18});
      std::vector<double> lo(n), hi(n);
      for (std::size_t k = 0; k < n; ++k) {
        lo[k] = -sig[i][k];
        hi[k] = sig[i][k];
      }
      ax.bands.push_back({"±1σ predicted", t, lo, hi, plot::palette(0), 0.22});
      if (r.run.has_truth)
        ax.series.push_back({"error", t, err[i], plot::palette(1), plot::LineStyle::Solid, plot::Marker::None, 1.6});
      ax.legend = i == 0 ? plot::LegendPos::Best : plot::LegendPos::None;
      fig.axes.push_back(ax);
    }
    return fig;
  };
  const double tEnd = n ? t.back() : 1.0;
  plot::savePng(figure(0.0, tEnd,
                       (r.run.has_truth ? "Navigation errors (estimate − truth), filter model: "
                                        : "Predicted ±1σ (no ground truth in the rawlog), filter model: ") +
                           r.model_source),
                out.stage("errors_full.png").string());
  for (std::size_t i = 0; i < r.cfg.outages.size(); ++i) {
    const auto& o = r.cfg.outages[i];
    const double a = std::max(0.0, o.start_s - 0.1 * o.duration_s());
    const double b = std::min(tEnd, o.start_s + 1.1 * o.duration_s());
    const std::string name = "errors_outage_" + std::to_string(i + 1) + ".png";
    plot::savePng(figure(a, b, "GNSS outage " + std::to_string(i + 1) + ": " + formatNumber(o.duration_s(), 10) + " s from " +
                                   formatNumber(o.start_s, 10) + " s — errors and ±1σ"),
                  out.stage(name).string());
  }
}


}  // namespace

std::string solutionCsv(const ReplayResult& r) {
  std::ostringstream o;
  o << "time_s,lat_deg,lon_deg,h_m,vN_mps,vE_mps,vD_mps,roll_deg,pitch_deg,yaw_deg,"
       "sig_pN_m,sig_pE_m,sig_pD_m,sig_vN_mps,sig_vE_mps,sig_vD_mps,sig_roll_deg,sig_pitch_deg,sig_yaw_deg,"
       "err_pN_m,err_pE_m,err_pD_m,err_vN_mps,err_vE_mps,err_vD_mps,err_roll_deg,err_pitch_deg,err_yaw_deg,"
       "nees_pos,nees_vel,nees_att,nees_all,gnss\n";
  o << std::setprecision(10);
  for (std::size_t k = 0; k < r.run.epochs.size(); ++k) {
    const auto& e = r.run.epochs[k];
    const auto& x = r.estimate[k];
    const Eigen::Vector3d rpy = x.rollPitchYaw() / kDeg;
    const bool truth = r.run.has_truth;
    const Eigen::Vector3d se = eulerSigma(truth ? r.truth[k] : x, e.sigma.segment<3>(6)) / kDeg;
    const Eigen::Vector3d ee = truth ? Eigen::Vector3d(eulerError(x, r.truth[k]) / kDeg) : Eigen::Vector3d::Zero();
    bool gnss = true;
    for (const auto& w : r.cfg.outages)
      if (e.t - r.t_zero > w.start_s + 1e-9 && e.t - r.t_zero <= w.end_s + 1e-9) gnss = false;
    o << e.t - r.t_zero << ',' << std::setprecision(12) << x.lat / kDeg << ',' << x.lon / kDeg << ','
      << std::setprecision(10) << x.h << ',' << x.v_N[0] << ',' << x.v_N[1] << ',' << x.v_N[2] << ',' << rpy[0]
      << ',' << rpy[1] << ',' << rpy[2];
    for (int i = 0; i < 6; ++i) o << ',' << e.sigma[i];
    for (int i = 0; i < 3; ++i) o << ',' << se[i];
    if (truth) {
      for (int i = 0; i < 6; ++i) o << ',' << e.err[i];
      for (int i = 0; i < 3; ++i) o << ',' << ee[i];
      for (int i = 0; i < 4; ++i) o << ',' << e.nees[i];
    } else {
      o << ",,,,,,,,,,,,,";  // no ground truth: errors and NEES empty
    }
    o << ',' << (gnss ? 1 : 0) << '\n';
  }
  return o.str();
}

std::string summaryJson(const ReplayResult& r) {
  using nlohmann::json;
  json j;
  j["rawlog"] = r.cfg.rawlog;
  j["filter_model"] = r.model_source;
  j["imu_rate_hz"] = r.imu_rate_hz;
  j["time_zero_note"] = "times are seconds from the start of the IMU data (first IMU timestamp minus one period)";
  j["propagate_every"] = r.cfg.propagate_every;
  j["gnss_updates"] = r.run.gnss_updates;
  j["baro_updates"] = r.run.baro_updates;
  j["imu_steps"] = r.run.steps;
  j["ekf_states"] = r.run.states;
  j["filter_wall_s"] = r.run.wall_s;
  j["rawlog_read_cpu_s"] = r.read_s;
  j["ground_truth"] = r.run.has_truth;
  try {
    const YAML::Node s = YAML::Load(r.scenario_yaml)["navimpact_scenario"];
    if (s) {
      json seeds;
      for (const char* k : {"imu", "gnss", "baro"})
        if (s[k] && s[k]["seed"]) seeds[k] = s[k]["seed"].as<std::uint64_t>();
      j["scenario_seeds"] = seeds;
      if (s["imu"] && s["imu"]["model"]) j["scenario_imu_model"] = s["imu"]["model"].as<std::string>();
      if (s["imu"] && s["imu"]["errors"]) j["scenario_imu_errors"] = s["imu"]["errors"].as<std::string>();
    }
  } catch (const YAML::Exception&) {
  }
  const auto& ep = r.run.epochs;
  auto block = [&](std::size_t k, int b) { return ep[k].err.segment<3>(3 * b); };
  json outs = json::array();
  for (std::size_t i = 0; i < r.run.outages.size(); ++i) {
    const auto& o = r.run.outages[i];
    json jo;
    jo["start_s"] = r.cfg.outages[i].start_s;
    jo["duration_s"] = r.cfg.outages[i].duration_s();
    if (o.end_epoch < 0) {
      jo["note"] = "no recorded epoch inside the outage";
      outs.push_back(jo);
      continue;
    }
    const std::size_t ke = static_cast<std::size_t>(o.end_epoch);
    if (!r.run.has_truth) {  // predicted sigmas only
      const auto& e = ep[ke];
      const Eigen::Vector3d attSig = eulerSigma(r.estimate[ke], e.sigma.segment<3>(6)) / kDeg;
      jo["end_epoch_s"] = e.t - r.t_zero;
      jo["note"] = "no ground truth: predicted sigmas only";
      jo["position"] = {{"horizontal_sigma_end_m", e.sigma.head<2>().norm()}, {"vertical_sigma_end_m", e.sigma[2]}};
      jo["velocity"] = {{"horizontal_sigma_end_mps", e.sigma.segment<2>(3).norm()},
                        {"vertical_sigma_end_mps", e.sigma[5]}};
      jo["attitude_deg"] = {{"roll_pitch_yaw_sigma_end", {attSig[0], attSig[1], attSig[2]}}};
      outs.push_back(jo);
      continue;
    }
    double maxPh = 0, maxPv = 0, maxVh = 0, maxVv = 0, neesSum = 0;
    Eigen::Vector3d maxAtt = Eigen::Vector3d::Zero();
    std::array<double, 4> neesB{};
    int n = 0;
    for (std::size_t k = 0; k <= ke; ++k) {
      if (ep[k].t <= o.window.start_s) continue;
      maxPh = std::max(maxPh, block(k, 0).head<2>().norm());
      maxPv = std::max(maxPv, std::abs(block(k, 0)[2]));
      maxVh = std::max(maxVh, block(k, 1).head<2>().norm());
      maxVv = std::max(maxVv, std::abs(block(k, 1)[2]));
      maxAtt = maxAtt.cwiseMax(eulerError(r.estimate[k], r.truth[k]).cwiseAbs() / kDeg);
      for (int b = 0; b < 4; ++b) neesB[b] += ep[k].nees[b];
      neesSum += ep[k].nees[3];
      ++n;
    }
    const auto& e = ep[ke];
    const Eigen::Vector3d attEnd = eulerError(r.estimate[ke], r.truth[ke]) / kDeg;
    const Eigen::Vector3d attSig = eulerSigma(r.truth[ke], e.sigma.segment<3>(6)) / kDeg;
    jo["end_epoch_s"] = e.t - r.t_zero;
    jo["position"] = {{"horizontal_error_end_m", e.err.head<2>().norm()},
                      {"vertical_error_end_m", std::abs(e.err[2])},
                      {"horizontal_error_max_m", maxPh},
                      {"vertical_error_max_m", maxPv},
                      {"horizontal_sigma_end_m", e.sigma.head<2>().norm()},
                      {"vertical_sigma_end_m", e.sigma[2]}};
    jo["velocity"] = {{"horizontal_error_end_mps", e.err.segment<2>(3).norm()},
                      {"vertical_error_end_mps", std::abs(e.err[5])},
                      {"horizontal_error_max_mps", maxVh},
                      {"vertical_error_max_mps", maxVv},
                      {"horizontal_sigma_end_mps", e.sigma.segment<2>(3).norm()},
                      {"vertical_sigma_end_mps", e.sigma[5]}};
    jo["attitude_deg"] = {{"roll_pitch_yaw_error_end", {attEnd[0], attEnd[1], attEnd[2]}},
                          {"roll_pitch_yaw_abs_error_max", {maxAtt[0], maxAtt[1], maxAtt[2]}},
                          {"roll_pitch_yaw_sigma_end", {attSig[0], attSig[1], attSig[2]}}};
    jo["mean_nees"] = {{"position_3dof", neesB[0] / n}, {"velocity_3dof", neesB[1] / n},
                       {"attitude_3dof", neesB[2] / n}, {"all_9dof", neesSum / n}, {"epochs", n}};
    outs.push_back(jo);
  }
  j["outages"] = outs;
  if (!r.run.has_truth) {
    j["note"] = "the rawlog has no ground truth (label GT): errors, NEES and RMS are not available; "
                "solution.csv holds the estimate and the predicted sigmas, its error and NEES columns are empty";
    j["epochs"] = ep.size();
    j["notices"] = r.notices;
    return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  }
  // Overall RMS over all epochs.
  double sPh = 0, sPv = 0, sV = 0;
  Eigen::Vector3d sA = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < ep.size(); ++k) {
    sPh += block(k, 0).head<2>().squaredNorm();
    sPv += block(k, 0)[2] * block(k, 0)[2];
    sV += block(k, 1).squaredNorm();
    sA += (eulerError(r.estimate[k], r.truth[k]) / kDeg).cwiseAbs2();
  }
  const double n = std::max<std::size_t>(1, ep.size());
  j["overall_rms"] = {{"horizontal_position_m", std::sqrt(sPh / n)},
                      {"vertical_position_m", std::sqrt(sPv / n)},
                      {"velocity_3d_mps", std::sqrt(sV / n)},
                      {"roll_pitch_yaw_deg", {std::sqrt(sA[0] / n), std::sqrt(sA[1] / n), std::sqrt(sA[2] / n)}},
                      {"epochs", ep.size()}};
  j["notices"] = r.notices;
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

std::string replaySummary(const ReplayResult& r) {
  std::string s;
  char b[512];
  for (const auto& n : r.notices) s += "notice: " + n + "\n";
  std::snprintf(b, sizeof b,
                "replayed %s: %zu IMU steps at %g Hz, %zu GNSS and %zu baro updates, filter model %s "
                "(rawlog read %.3f s CPU, filter %.3f s)\n",
                r.cfg.rawlog.c_str(), r.run.steps, r.imu_rate_hz, r.run.gnss_updates, r.run.baro_updates,
                r.model_source.c_str(), r.read_s, r.run.wall_s);
  s += b;
  if (!r.run.has_truth) s += "no ground truth in the rawlog: estimate and predicted sigmas only\n";
  for (std::size_t i = 0; i < r.run.outages.size(); ++i) {
    const auto& w = r.run.outages[i];
    if (w.end_epoch < 0) continue;
    const auto& e = r.run.epochs[static_cast<std::size_t>(w.end_epoch)];
    const auto& o = r.cfg.outages[i];
    if (!r.run.has_truth)
      std::snprintf(b, sizeof b, "outage %zu (%g s from %g s): predicted horizontal 1-sigma at end %.2f m, vertical %.2f m\n",
                    i + 1, o.duration_s(), o.start_s, e.sigma.head<2>().norm(), e.sigma[2]);
    else
      std::snprintf(b, sizeof b,
                    "outage %zu (%g s from %g s): horizontal error at end %.2f m (1-sigma %.2f m), max %.2f m; "
                    "vertical %.2f m (1-sigma %.2f m)\n",
                    i + 1, o.duration_s(), o.start_s, e.err.head<2>().norm(), e.sigma.head<2>().norm(),
                    w.max_drift_h, std::abs(e.err[2]), e.sigma[2]);
    s += b;
  }
  return s;
}

void writeReplayOutputs(const ReplayResult& r, OutputSet& out) {
  out.writeText("solution.csv", solutionCsv(r));
  out.writeText("summary.json", summaryJson(r));
  writeReplayFigures(r, out);
}

}  // namespace navimpact::report
