// Outputs of navimpact replay: solution.csv, summary.json and the error figures.
#include "navimpact/report/replay_report.hpp"

#include <yaml-cpp/yaml.h>

#include <nlohmann/json.hpp>

#include <array>
#include <cstdio>
#include <cmath>
#include <limits>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/yaml_load.hpp"
#include "navimpact/plot/figure.hpp"
#include "navimpact/report/timing.hpp"

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

constexpr const char* kSolutionHeader =
    "time_s,lat_deg,lon_deg,h_m,vN_mps,vE_mps,vD_mps,roll_deg,pitch_deg,yaw_deg,"
    "sig_pN_m,sig_pE_m,sig_pD_m,sig_vN_mps,sig_vE_mps,sig_vD_mps,sig_roll_deg,sig_pitch_deg,sig_yaw_deg,"
    "err_pN_m,err_pE_m,err_pD_m,err_vN_mps,err_vE_mps,err_vD_mps,err_roll_deg,err_pitch_deg,err_yaw_deg,"
    "nees_pos,nees_vel,nees_att,nees_all,gnss\n";

/// Per-outage zoomed figures are written for the first this many outages.
constexpr std::size_t kMaxOutageFigures = 12;

/// One epoch as the figures draw it.
struct FigurePoint {
  double t_abs = 0.0, t = 0.0;            ///< filter time, time from time zero [s]
  std::array<double, 9> err{}, sig{};     ///< errors and 1-sigma as plotted (attitude in deg, roll/pitch/yaw)
  double est_n = 0.0, est_e = 0.0;        ///< estimate, tangent plane at the first epoch [m]
  double ref_n = 0.0, ref_e = 0.0;        ///< reference, same plane [m]
};

/// At most `cap` points of a series: every stride-th point, the stride doubled
/// (every other kept point dropped) whenever the count would exceed the cap;
/// all points while there are at most `cap`.
class Decimated {
 public:
  explicit Decimated(std::size_t cap) : cap_(cap) {}
  void add(const FigurePoint& p) {
    last_ = p;
    if (seen_++ % stride_ != 0) return;
    pts_.push_back(p);
    if (pts_.size() <= cap_) return;
    std::size_t j = 0;
    for (std::size_t i = 0; i < pts_.size(); i += 2) pts_[j++] = pts_[i];
    pts_.resize(j);
    stride_ *= 2;
  }
  /// The kept points, the last point added included.
  std::vector<FigurePoint> points() const {
    std::vector<FigurePoint> v = pts_;
    if (seen_ > 0 && (seen_ - 1) % stride_ != 0) v.push_back(last_);
    return v;
  }
  std::size_t stride() const { return stride_; }
  std::size_t seen() const { return seen_; }

 private:
  std::size_t cap_;
  std::size_t stride_ = 1, seen_ = 0;
  std::vector<FigurePoint> pts_;
  FigurePoint last_;
};

/// Points drawn per series of errors_full.png and trajectory.png (a run with
/// more epochs is decimated: every 2^k-th epoch, the last one included).
constexpr std::size_t kMaxFigurePoints = 40000;
/// Points kept per zoomed outage figure when the whole run is decimated.
constexpr std::size_t kMaxZoomPoints = 8000;

/// What a zoomed outage figure shows: its time range and the points in it
/// (one before and one after, so the lines reach the edges).
struct Zoom {
  double a = 0.0, b = 0.0;   ///< [s] from time zero
  Decimated pts{kMaxZoomPoints};
  bool closed = false;
};

/// @p m = the larger of @p m and @p v over the known values (NaN: none known
/// yet, or a part the reference does not have: it stays unknown, not 0).
void keepMax(double& m, double v) {
  if (!std::isnan(v) && (std::isnan(m) || v > m)) m = v;
}

/// Running statistics of one outage over its epochs (summary.json).
struct OutageStats {
  static constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();
  double maxPh = kUnknown, maxPv = kUnknown, maxVh = kUnknown, maxVv = kUnknown, neesSum = 0;
  Eigen::Vector3d maxAtt = Eigen::Vector3d::Constant(kUnknown);
  std::array<double, 4> neesB{};
  int n = 0;
  ins::NavState endTruth;  ///< the reference at its end epoch
};

}  // namespace

/// Everything written per epoch and what the summary and figures keep of it.
struct ReplayWriter::State {
  std::ostream* csv = nullptr;
  std::ofstream file;
  std::vector<char> buffer;
  std::filesystem::path csvPath;
  bool begun = false;
  // summary
  std::vector<OutageStats> outages;  // one per outage known so far
  std::vector<std::size_t> live;     // outages that may still contain an epoch
  double sPh = 0, sPv = 0, sV = 0;
  Eigen::Vector3d sA = Eigen::Vector3d::Zero();
  std::size_t epochs = 0;
  // figures
  bool haveOrigin = false;
  earth::Geodetic o0;
  Decimated all{kMaxFigurePoints};
  std::vector<Zoom> zooms;
  std::optional<FigurePoint> prev;

  void begin(const ReplayResult& r) {
    begun = true;
    (void)r;
  }

  void epoch(const ReplayResult& r, const NavEpoch& e, const ins::NavState* truth, const std::vector<Outage>& windows) {
    const ins::NavState& x = e.est;
    const bool hasTruth = truth != nullptr;
    // Euler sigmas about the true attitude, or the estimate's where the reference has none
    const bool truthAttitude = hasTruth && truth->q_BtoN.coeffs().allFinite();
    const Eigen::Vector3d se = eulerSigma(truthAttitude ? *truth : x, e.sigma.segment<3>(6)) / kDeg;
    const Eigen::Vector3d ee = hasTruth ? Eigen::Vector3d(eulerError(x, *truth) / kDeg) : Eigen::Vector3d::Zero();
    // solution.csv
    if (csv) {
      std::ostream& o = *csv;
      const Eigen::Vector3d rpy = x.rollPitchYaw() / kDeg;
      bool gnss = true;
      for (const auto& w : r.cfg.outages)
        if (e.t - r.t_zero > w.start_s + 1e-9 && e.t - r.t_zero <= w.end_s + 1e-9) gnss = false;
      o << std::setprecision(10);
      o << e.t - r.t_zero << ',' << std::setprecision(12) << x.lat / kDeg << ',' << x.lon / kDeg << ','
        << std::setprecision(10) << x.h << ',' << x.v_N[0] << ',' << x.v_N[1] << ',' << x.v_N[2] << ',' << rpy[0]
        << ',' << rpy[1] << ',' << rpy[2];
      for (int i = 0; i < 6; ++i) o << ',' << e.sigma[i];
      for (int i = 0; i < 3; ++i) o << ',' << se[i];
      if (hasTruth) {
        for (int i = 0; i < 6; ++i) o << ',' << e.err[i];
        for (int i = 0; i < 3; ++i) o << ',' << ee[i];
        for (int i = 0; i < 4; ++i) o << ',' << e.nees[i];
      } else {
        o << ",,,,,,,,,,,,,";  // no ground truth: errors and NEES empty
      }
      o << ',' << (gnss ? 1 : 0) << '\n';
    }
    // per-outage statistics over the epochs in (start, end]
    while (outages.size() < windows.size()) {
      live.push_back(outages.size());
      outages.emplace_back();
    }
    for (std::size_t j = 0; j < live.size();) {
      const Outage& w = windows[live[j]];
      if (e.t > w.end_s + 1e-9) {
        live.erase(live.begin() + static_cast<std::ptrdiff_t>(j));
        continue;
      }
      OutageStats& st = outages[live[j]];
      ++j;
      if (e.t <= w.start_s || !hasTruth) continue;
      const auto block = [&](int b) { return e.err.segment<3>(3 * b); };
      keepMax(st.maxPh, block(0).head<2>().norm());
      keepMax(st.maxPv, std::abs(block(0)[2]));
      keepMax(st.maxVh, block(1).head<2>().norm());
      keepMax(st.maxVv, std::abs(block(1)[2]));
      const Eigen::Vector3d att = eulerError(x, *truth).cwiseAbs() / kDeg;
      for (int k = 0; k < 3; ++k) keepMax(st.maxAtt[k], att[k]);
      for (int b = 0; b < 4; ++b) st.neesB[b] += e.nees[b];
      st.neesSum += e.nees[3];
      ++st.n;
      st.endTruth = *truth;
    }
    // overall RMS
    if (hasTruth) {
      const auto block = [&](int b) { return e.err.segment<3>(3 * b); };
      sPh += block(0).head<2>().squaredNorm();
      sPv += block(0)[2] * block(0)[2];
      sV += block(1).squaredNorm();
      sA += (eulerError(x, *truth) / kDeg).cwiseAbs2();
    }
    ++epochs;
    // figures
    if (!haveOrigin) {
      o0 = hasTruth ? truth->geodetic() : x.geodetic();
      haveOrigin = true;
    }
    FigurePoint p;
    p.t_abs = e.t;
    p.t = e.t - r.t_zero;
    for (int i = 0; i < 6; ++i) {
      p.err[i] = e.err[i];
      p.sig[i] = e.sigma[i];
    }
    for (int i = 0; i < 3; ++i) {
      p.err[6 + i] = ee[i];
      p.sig[6 + i] = se[i];
    }
    const Eigen::Vector3d pe = earth::geodeticToNed(o0, x.geodetic());
    p.est_n = pe.x();
    p.est_e = pe.y();
    if (hasTruth) {
      const Eigen::Vector3d q = earth::geodeticToNed(o0, truth->geodetic());
      p.ref_n = q.x();
      p.ref_e = q.y();
    }
    all.add(p);
    for (std::size_t i = zooms.size(); i < r.cfg.outages.size() && i < kMaxOutageFigures; ++i) {
      const auto& o = r.cfg.outages[i];
      Zoom z;
      z.a = std::max(0.0, o.start_s - 0.1 * o.duration_s());
      z.b = o.start_s + 1.1 * o.duration_s();
      zooms.push_back(std::move(z));
    }
    for (auto& z : zooms) {
      if (z.closed || p.t < z.a) continue;
      if (z.pts.seen() == 0 && prev) z.pts.add(*prev);
      z.pts.add(p);
      if (p.t > z.b) z.closed = true;
    }
    prev = p;
  }
};

namespace {

/// The 3x3 error figure (error and ±1σ per axis) over [x0, x1] from @p pts.
plot::Figure errorsFigure(const ReplayResult& r, const std::vector<FigurePoint>& pts, double x0, double x1,
                          const std::string& title) {
  const char* names[9] = {"north", "east", "down", "north", "east", "down", "roll", "pitch", "yaw"};
  const char* units[3] = {"position error [m]", "velocity error [m/s]", "attitude error [deg]"};
  const std::size_t n = pts.size();
  std::vector<double> t(n);
  for (std::size_t k = 0; k < n; ++k) t[k] = pts[k].t;
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
    for (const auto& o : r.cfg.outages)  // one legend entry for all of them
      ax.spans.push_back({ax.spans.empty() ? "GNSS outage" : "", o.start_s, o.end_s, {128, 128, 128}, 0.18});
    std::vector<double> lo(n), hi(n), err(n);
    for (std::size_t k = 0; k < n; ++k) {
      lo[k] = -pts[k].sig[i];
      hi[k] = pts[k].sig[i];
      err[k] = pts[k].err[i];
    }
    ax.bands.push_back({"±1σ predicted", t, lo, hi, plot::palette(0), 0.22});
    if (r.run.has_truth)
      ax.series.push_back({"error", t, err, plot::palette(1), plot::LineStyle::Solid, plot::Marker::None, 1.6});
    ax.legend = i == 0 ? plot::LegendPos::Best : plot::LegendPos::None;
    fig.axes.push_back(ax);
  }
  return fig;
}

/// Horizontal track in metres from the first epoch: estimate (and reference),
/// the estimate during each outage drawn over it, its end marked.
void writeTrajectoryFigure(const ReplayResult& r, const std::vector<FigurePoint>& pts, const earth::Geodetic& o0,
                           OutputSet& out) {
  if (pts.empty()) return;
  plot::Axes ax;
  ax.xlabel = "east [m]";
  ax.ylabel = "north [m]";
  plot::Series est{"estimate", {}, {}, plot::palette(0), plot::LineStyle::Solid, plot::Marker::None, 1.4};
  plot::Series ref{"reference", {}, {}, plot::palette(6), plot::LineStyle::Dashed, plot::Marker::None, 1.2};
  plot::Series ends{"outage end (estimate)", {}, {}, plot::palette(1), plot::LineStyle::None, plot::Marker::Cross, 2.0};
  std::vector<plot::Series> outs;
  for (const auto& p : pts) {
    est.x.push_back(p.est_e);
    est.y.push_back(p.est_n);
    if (r.run.has_truth) {
      ref.x.push_back(p.ref_e);
      ref.y.push_back(p.ref_n);
    }
  }
  for (std::size_t i = 0; i < r.run.outages.size(); ++i) {
    const auto& w = r.run.outages[i];
    plot::Series s{i == 0 ? "estimate in a GNSS outage" : "", {}, {}, plot::palette(1), plot::LineStyle::Solid,
                   plot::Marker::None, 2.4};
    for (const auto& p : pts)
      if (p.t_abs > w.window.start_s && p.t_abs <= w.window.end_s + 1e-9) {
        s.x.push_back(p.est_e);
        s.y.push_back(p.est_n);
      }
    if (w.end_epoch >= 0) {
      const Eigen::Vector3d p = earth::geodeticToNed(o0, w.end.est.geodetic());
      ends.x.push_back(p.y());
      ends.y.push_back(p.x());
    }
    if (!s.x.empty()) outs.push_back(s);
  }
  if (r.run.has_truth) ax.series.push_back(ref);
  ax.series.push_back(est);
  for (auto& s : outs) ax.series.push_back(s);
  if (!ends.x.empty()) ax.series.push_back(ends);
  // equal scales: pad the shorter extent
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const auto& s : ax.series)
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      x0 = std::min(x0, s.x[k]);
      x1 = std::max(x1, s.x[k]);
      y0 = std::min(y0, s.y[k]);
      y1 = std::max(y1, s.y[k]);
    }
  const int W = 1400, H = 1100;
  const double half = 0.55 * std::max({x1 - x0, (y1 - y0) * W / H, 1.0});
  const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
  ax.xlim = std::make_pair(cx - half, cx + half);
  ax.ylim = std::make_pair(cy - half * H / W, cy + half * H / W);
  plot::Figure fig;
  fig.width = W;
  fig.height = H;
  fig.title = "Horizontal track" + std::string(r.run.has_truth ? " against the reference" : "") + ", " +
              std::to_string(r.run.outages.size()) + " GNSS outage(s) in red";
  fig.axes.push_back(ax);
  plot::savePng(fig, out.stage("trajectory.png").string());
}

/// Error at each outage end against the filter's predicted sigma (reference
/// sigma included), horizontal and vertical, with the 1/2/3-sigma lines.
void writeOutageEndFigure(const RunScore& sc, OutputSet& out) {
  plot::Figure fig;
  fig.width = 1800;
  fig.height = 800;
  fig.rows = 1;
  fig.cols = 2;
  fig.title = "Error at the end of each GNSS outage against its predicted σ (" +
              std::to_string(sc.outages.size()) + " outages)";
  const double rh = sc.reference.sigma_h_m, rv = sc.reference.sigma_v_m;
  for (int v = 0; v < 2; ++v) {
    plot::Axes ax;
    ax.title = v == 0 ? "horizontal" : "vertical";
    ax.xlabel = v == 0 ? "predicted horizontal σ (√(σN²+σE²), reference included) [m]"
                       : "predicted vertical σ (reference included) [m]";
    ax.ylabel = "error at outage end [m]";
    plot::Series pts{"outages", {}, {}, plot::palette(0), plot::LineStyle::None, plot::Marker::FilledCircle, 2.0};
    double mx = 0.0;
    for (const auto& o : sc.outages) {
      const double sig = v == 0 ? std::sqrt(o.horizontal_sigma_m * o.horizontal_sigma_m + 2.0 * rh * rh)
                                : std::hypot(o.vertical_sigma_m, rv);
      pts.x.push_back(sig);
      pts.y.push_back(v == 0 ? o.horizontal_error_m : o.vertical_error_m);
      mx = std::max({mx, sig, pts.y.back()});
    }
    mx = std::max(mx, 1e-3) * 1.05;
    for (int k = 1; k <= 3; ++k)
      ax.series.push_back({std::to_string(k) + "σ", {0.0, mx}, {0.0, k * mx}, plot::palette(k + 1),
                           plot::LineStyle::Dashed, plot::Marker::None, 1.4});
    ax.series.push_back(pts);
    ax.xlim = std::make_pair(0.0, mx);
    ax.ylim = std::make_pair(0.0, mx * 1.5);
    fig.axes.push_back(ax);
  }
  plot::savePng(fig, out.stage("outage_end_error.png").string());
}

std::string summaryFrom(const ReplayResult& r, const ReplayWriter::State& st) {
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
  j["ground_truth"] = r.run.has_truth;
  try {
    const YAML::Node s = loadYaml(r.scenario_yaml)["navimpact_scenario"];
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
    const NavEpoch& e = o.end;
    const ins::NavState& estEnd = o.end.est;
    if (r.score) {  // the scored outage (reference sigma counted in the NEES)
      for (const auto& q : r.score->outages)
        if (std::abs(q.start_s - r.cfg.outages[i].start_s) < 1e-9 &&
            std::abs(q.duration_s - r.cfg.outages[i].duration_s()) < 1e-6) {
          jo["end_s"] = q.end_s;
          jo["horizontal_error_m"] = q.horizontal_error_m;
          jo["vertical_error_m"] = q.vertical_error_m;
          jo["horizontal_sigma_m"] = q.horizontal_sigma_m;
          jo["vertical_sigma_m"] = q.vertical_sigma_m;
          jo["max_drift_horizontal_m"] = q.max_drift_h_m;
          jo["max_drift_vertical_m"] = q.max_drift_v_m;
          jo["nees"] = q.nees;
          jo["nees_in_95_band"] = q.nees_in_band;
          break;
        }
    }
    if (!r.run.has_truth) {  // predicted sigmas only
      const Eigen::Vector3d attSig = eulerSigma(estEnd, e.sigma.segment<3>(6)) / kDeg;
      jo["end_epoch_s"] = e.t - r.t_zero;
      jo["note"] = "no ground truth: predicted sigmas only";
      jo["position"] = {{"horizontal_sigma_end_m", e.sigma.head<2>().norm()}, {"vertical_sigma_end_m", e.sigma[2]}};
      jo["velocity"] = {{"horizontal_sigma_end_mps", e.sigma.segment<2>(3).norm()},
                        {"vertical_sigma_end_mps", e.sigma[5]}};
      jo["attitude_deg"] = {{"roll_pitch_yaw_sigma_end", {attSig[0], attSig[1], attSig[2]}}};
      outs.push_back(jo);
      continue;
    }
    const OutageStats& os = st.outages.at(i);
    const double maxPh = os.maxPh, maxPv = os.maxPv, maxVh = os.maxVh, maxVv = os.maxVv, neesSum = os.neesSum;
    const Eigen::Vector3d& maxAtt = os.maxAtt;
    const std::array<double, 4>& neesB = os.neesB;
    const int n = os.n;
    const Eigen::Vector3d attEnd = eulerError(estEnd, os.endTruth) / kDeg;
    const Eigen::Vector3d attSig =
        eulerSigma(os.endTruth.q_BtoN.coeffs().allFinite() ? os.endTruth : estEnd, e.sigma.segment<3>(6)) / kDeg;
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
  if (r.cfg.extra_states.any()) {
    // the filter's extra states at the end of the run (SI; state_layout.hpp)
    const filter::ExtraStates& x = r.cfg.extra_states;
    const auto& e = r.run.extra_estimates;
    const auto& sg = r.run.extra_sigmas;
    auto v3 = [](const Eigen::Vector3d& v) { return json::array({v(0), v(1), v(2)}); };
    json ex = json::object();
    if (x.gyro_scale_sigma > 0) ex["gyro_scale"] = {{"estimate", v3(e.gyro_scale)}, {"sigma", v3(sg.gyro_scale)}, {"prior_sigma", x.gyro_scale_sigma}, {"initial", v3(x.gyro_scale0)}};
    if (x.acc_scale_sigma > 0) ex["acc_scale"] = {{"estimate", v3(e.acc_scale)}, {"sigma", v3(sg.acc_scale)}, {"prior_sigma", x.acc_scale_sigma}, {"initial", v3(x.acc_scale0)}};
    if (x.gyro_misalignment_sigma_rad > 0)
      ex["gyro_misalignment_rad"] = {{"estimate", v3(e.gyro_misalignment_rad)}, {"sigma", v3(sg.gyro_misalignment_rad)}, {"prior_sigma", x.gyro_misalignment_sigma_rad}, {"initial", v3(x.gyro_misalignment0_rad)}};
    if (x.acc_misalignment_sigma_rad > 0)
      ex["acc_misalignment_rad"] = {{"estimate", v3(e.acc_misalignment_rad)}, {"sigma", v3(sg.acc_misalignment_rad)}, {"prior_sigma", x.acc_misalignment_sigma_rad}, {"initial", v3(x.acc_misalignment0_rad)}};
    if (x.lever_arm_sigma_m > 0)
      ex["lever_arm_error_B_m"] = {{"estimate", v3(e.lever_arm_error_B_m)}, {"sigma", v3(sg.lever_arm_error_B_m)}, {"prior_sigma", x.lever_arm_sigma_m}, {"initial", v3(x.lever_arm_error0_m)}};
    if (x.time_offset_sigma_s > 0)
      ex["time_offset_s"] = {{"estimate", e.time_offset_s}, {"sigma", sg.time_offset_s}, {"prior_sigma", x.time_offset_sigma_s}, {"initial", x.time_offset0_s}};
    j["extra_states"] = ex;
  }
  // gate events, the first 1000 of each kind; re-admissions with the factor P was scaled by
  auto gateEvents = [&](const std::vector<RejectedUpdate>& v, bool inflation) {
    json a = json::array();
    for (std::size_t k = 0; k < v.size() && k < 1000; ++k) {
      json e = {{"t_s", v[k].t - r.t_zero}, {"kind", v[k].kind}, {"nis", v[k].nis}, {"gate", v[k].gate}};
      if (inflation) e["p_inflation"] = v[k].inflation;
      a.push_back(e);
    }
    return a;
  };
  j["rejected_updates"] = r.run.rejected.size();
  j["rejected"] = gateEvents(r.run.rejected, false);
  j["readmitted_updates"] = r.run.readmitted.size();
  j["readmitted"] = gateEvents(r.run.readmitted, true);
  j["zupt_updates"] = r.run.zupt_updates;
  j["nhc_updates"] = r.run.nhc_updates;
  j["filter_start_s"] = r.aided_from_s;
  if (r.alignment) {
    const auto& a = *r.alignment;
    j["alignment"] = {{"phase", "aligning"},
                      {"start_s", a.t_start - r.t_zero},
                      {"end_s", a.t_end - r.t_zero},
                      {"levelling", a.levelling},
                      {"level_span_s", a.level_span_s},
                      {"heading", a.heading},
                      {"heading_at_s", a.heading_t - r.t_zero},
                      {"course_speed_mps", a.course_speed_mps},
                      {"roll_pitch_yaw_deg", {a.rpy[0] / kDeg, a.rpy[1] / kDeg, a.rpy[2] / kDeg}},
                      {"roll_pitch_yaw_sigma_deg", {a.sigma_rpy[0] / kDeg, a.sigma_rpy[1] / kDeg, a.sigma_rpy[2] / kDeg}},
                      {"static_at_end", a.static_at_end},
                      {"notes", a.notes}};
  }
  if (r.score) {
    const auto& sc = *r.score;
    auto fin = [](double x) { return std::isfinite(x) ? json(x) : json(nullptr); };
    j["reference_errors"] = {{"horizontal_rms_m", fin(sc.horizontal_rms_m)},
                             {"vertical_rms_m", fin(sc.vertical_rms_m)},
                             {"velocity_rms_mps", fin(sc.velocity_rms_mps)},
                             {"attitude_rms_deg_psi_NED",
                              {fin(sc.attitude_rms_rad[0] / kDeg), fin(sc.attitude_rms_rad[1] / kDeg),
                               fin(sc.attitude_rms_rad[2] / kDeg)}},
                             {"epochs", sc.aided_epochs},
                             {"over", "reference epochs with GNSS (outside the outages, from the filter start)"},
                             {"reference_sigma_m", {{"horizontal", sc.reference.sigma_h_m},
                                                    {"vertical", sc.reference.sigma_v_m}}}};
    const auto& d = sc.distribution;
    j["outage_distribution"] = {
        {"count", d.count},
        {"horizontal_error_median_m", fin(d.median_h_m)},
        {"horizontal_error_p95_m", fin(d.p95_h_m)},
        {"vertical_error_median_m", fin(d.median_v_m)},
        {"vertical_error_p95_m", fin(d.p95_v_m)},
        {"coverage_1_2_3_sigma", {fin(d.coverage[0]), fin(d.coverage[1]), fin(d.coverage[2])}},
        {"coverage_expected", {d.coverage_expected[0], d.coverage_expected[1], d.coverage_expected[2]}},
        {"coverage_note", "fraction of the per-axis end errors (N, E, D) within k predicted sigma, reference sigma included"},
        {"mean_nees", fin(d.mean_nees)},
        {"mean_nees_95_band", {fin(d.mean_nees_lo), fin(d.mean_nees_hi)}},
        {"nees_in_95_band", d.nees_in_band},
        {"nees_95_band", {d.nees_band_lo, d.nees_band_hi}}};
  }
  if (!r.run.has_truth) {
    j["note"] = "the rawlog has no ground truth (label GT): errors, NEES and RMS are not available; "
                "solution.csv holds the estimate and the predicted sigmas, its error and NEES columns are empty";
    j["epochs"] = st.epochs;
    j["notices"] = r.notices;
    return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  }
  // Overall RMS over all epochs.
  const double sPh = st.sPh, sPv = st.sPv, sV = st.sV;
  const Eigen::Vector3d sA = st.sA;
  const double n = std::max<std::size_t>(1, st.epochs);
  j["overall_rms"] = {{"horizontal_position_m", std::sqrt(sPh / n)},
                      {"vertical_position_m", std::sqrt(sPv / n)},
                      {"velocity_3d_mps", std::sqrt(sV / n)},
                      {"roll_pitch_yaw_deg", {std::sqrt(sA[0] / n), std::sqrt(sA[1] / n), std::sqrt(sA[2] / n)}},
                      {"epochs", st.epochs}};
  j["notices"] = r.notices;
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace

ReplayWriter::ReplayWriter(OutputSet* out) : out_(out), st_(std::make_unique<State>()) {
  if (!out_) return;
  st_->csvPath = out_->stage("solution.csv");
  st_->buffer.resize(std::size_t(1) << 20);
  st_->file.rdbuf()->pubsetbuf(st_->buffer.data(), static_cast<std::streamsize>(st_->buffer.size()));
  st_->file.open(st_->csvPath, std::ios::binary);
  if (!st_->file) throw Error(st_->csvPath.string() + ": cannot write");
  st_->csv = &st_->file;
}

ReplayWriter::ReplayWriter(std::ostream& csv) : st_(std::make_unique<State>()) { st_->csv = &csv; }

ReplayWriter::~ReplayWriter() = default;

void ReplayWriter::begin(const ReplayResult& r) {
  st_->begin(r);
  if (st_->csv) *st_->csv << kSolutionHeader;
}

void ReplayWriter::epoch(const ReplayResult& r, const NavEpoch& e, const ins::NavState* truth,
                         const std::vector<Outage>& windows) {
  st_->epoch(r, e, truth, windows);
}

void ReplayWriter::feed(const ReplayResult& r) {
  std::vector<Outage> windows;
  for (const auto& o : r.run.outages) windows.push_back(o.window);
  begin(r);
  for (std::size_t k = 0; k < r.run.epochs.size(); ++k)
    epoch(r, r.run.epochs[k], r.run.has_truth ? &r.truth[k] : nullptr, windows);
}

std::string ReplayWriter::summary(const ReplayResult& r) const { return summaryFrom(r, *st_); }

void ReplayWriter::finish(const ReplayResult& r) {
  if (!out_) throw Error("replay writer: no output folder");
  State& st = *st_;
  st.file.flush();
  if (!st.file) throw Error(st.csvPath.string() + ": cannot write (disk full?)");
  st.file.close();
  out_->writeText("summary.json", summaryFrom(r, st));
  // wall-clock figures apart, so that two identical runs give identical result files
  writeTiming(*out_, {{"replay_wall_s", r.run.wall_s}, {"rawlog_read_wall_s", r.read_s}});
  // figures
  const std::vector<FigurePoint> pts = st.all.points();
  writeTrajectoryFigure(r, pts, st.o0, *out_);
  if (r.score && !r.score->outages.empty()) writeOutageEndFigure(*r.score, *out_);
  const double tEnd = pts.empty() ? 1.0 : pts.back().t;
  const std::string every =
      st.all.stride() > 1 ? " (one epoch in " + std::to_string(st.all.stride()) + " drawn)" : std::string();
  plot::savePng(errorsFigure(r, pts, 0.0, tEnd,
                             (r.run.has_truth ? "Navigation errors (estimate − truth), filter model: "
                                              : "Predicted ±1σ (no ground truth in the rawlog), filter model: ") +
                                 r.model_source + every),
                out_->stage("errors_full.png").string());
  for (std::size_t i = 0; i < r.cfg.outages.size() && i < kMaxOutageFigures; ++i) {
    const auto& o = r.cfg.outages[i];
    const double a = std::max(0.0, o.start_s - 0.1 * o.duration_s());
    const double b = std::min(tEnd, o.start_s + 1.1 * o.duration_s());
    const std::string name = "errors_outage_" + std::to_string(i + 1) + ".png";
    // all epochs when none was dropped (the same figure as over the whole series), else the zoom's own
    const std::vector<FigurePoint> zp = st.all.stride() == 1 || i >= st.zooms.size() ? pts : st.zooms[i].pts.points();
    plot::savePng(errorsFigure(r, zp, a, b,
                               "GNSS outage " + std::to_string(i + 1) + ": " + formatNumber(o.duration_s(), 10) +
                                   " s from " + formatNumber(o.start_s, 10) + " s — errors and ±1σ"),
                  out_->stage(name).string());
  }
}

std::string solutionCsv(const ReplayResult& r) {
  std::ostringstream o;
  ReplayWriter w(o);
  w.feed(r);
  return o.str();
}

std::string summaryJson(const ReplayResult& r) {
  ReplayWriter w(nullptr);
  w.feed(r);
  return w.summary(r);
}

std::string replaySummary(const ReplayResult& r) {
  std::string s;
  char b[512];
  for (const auto& n : r.notices) s += "notice: " + n + "\n";
  std::snprintf(b, sizeof b,
                "replayed %s: %zu IMU steps at %g Hz, %zu GNSS and %zu baro updates, filter model %s "
                "(%.3f s wall, %.3f s of it reading the rawlog)\n",
                r.cfg.rawlog.c_str(), r.run.steps, r.imu_rate_hz, r.run.gnss_updates, r.run.baro_updates,
                r.model_source.c_str(), r.run.wall_s, r.read_s);
  s += b;
  if (!r.run.has_truth) s += "no ground truth in the rawlog: estimate and predicted sigmas only\n";
  if (!r.run.rejected.empty()) {
    std::snprintf(b, sizeof b, "%zu update(s) rejected by the NIS gate (first at %.3f s, %s, NIS %.1f > %.1f)\n",
                  r.run.rejected.size(), r.run.rejected.front().t - r.t_zero, r.run.rejected.front().kind.c_str(),
                  r.run.rejected.front().nis, r.run.rejected.front().gate);
    s += b;
  }
  if (!r.run.readmitted.empty()) {
    double worst = 1.0;
    for (const auto& u : r.run.readmitted) worst = std::max(worst, u.inflation);
    std::snprintf(b, sizeof b,
                  "%zu update(s) re-admitted after %d rejections in a row, the covariance scaled by NIS/gate "
                  "first (up to %.3g; first at %.3f s, %s): the filter was overconfident\n",
                  r.run.readmitted.size(), r.cfg.gate_readmit_after, worst,
                  r.run.readmitted.front().t - r.t_zero, r.run.readmitted.front().kind.c_str());
    s += b;
  }
  if (r.score) {
    const auto& sc = *r.score;
    std::snprintf(b, sizeof b, "against the reference with GNSS: horizontal RMS %.3f m, vertical RMS %.3f m (%zu epochs)\n",
                  sc.horizontal_rms_m, sc.vertical_rms_m, sc.aided_epochs);
    s += b;
    const auto& d = sc.distribution;
    if (d.count > 1) {
      std::snprintf(b, sizeof b,
                    "%zu outages: horizontal error at end median %.2f m, p95 %.2f m; vertical median %.2f m, p95 %.2f m; "
                    "within 1/2/3 sigma %.0f/%.0f/%.0f %% (expected 68/95/99.7); mean NEES %.2f (95%% band %.2f..%.2f)\n",
                    d.count, d.median_h_m, d.p95_h_m, d.median_v_m, d.p95_v_m, 100 * d.coverage[0],
                    100 * d.coverage[1], 100 * d.coverage[2], d.mean_nees, d.mean_nees_lo, d.mean_nees_hi);
      s += b;
    }
  }
  for (std::size_t i = 0; i < r.run.outages.size() && i < 20; ++i) {
    const auto& w = r.run.outages[i];
    if (w.end_epoch < 0) continue;
    const auto& e = w.end;
    const auto& o = r.cfg.outages[i];
    if (!r.run.has_truth)
      std::snprintf(b, sizeof b, "outage %zu (%g s from %g s): predicted horizontal 1-sigma at end %.2f m, vertical %.2f m\n",
                    i + 1, o.duration_s(), o.start_s, e.sigma.head<2>().norm(), e.sigma[2]);
    else
      std::snprintf(b, sizeof b,
                    "outage %zu (%g s from %g s): horizontal error at end %.2f m (1-sigma %.2f m), max %.2f m; "
                    "vertical %.2f m (1-sigma %.2f m)",
                    i + 1, o.duration_s(), o.start_s, e.err.head<2>().norm(), e.sigma.head<2>().norm(),
                    w.max_drift_h, std::abs(e.err[2]), e.sigma[2]);
    s += b;
    // a sparse reference scores the outage at its last epoch inside, which may be well before the end
    const double into = e.t - r.t_zero - o.start_s;
    if (r.run.has_truth && o.duration_s() - into > 0.01 * o.duration_s()) {
      std::snprintf(b, sizeof b, " (at %.4g s of it: the last reference epoch inside)", into);
      s += b;
    }
    s += '\n';
  }
  return s;
}

void writeReplayOutputs(const ReplayResult& r, OutputSet& out) {
  ReplayWriter w(&out);
  w.feed(r);
  w.finish(r);
}

}  // namespace navimpact::report
