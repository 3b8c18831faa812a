// navimpact diagnose --run: measured outage errors of a real run against the
// distribution the simulation with the IMU model predicts (see run_diagnosis.hpp).
#include "navimpact/analysis/run_diagnosis.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/fisher_f.hpp>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/emulation/perfect_imu.hpp"
#include "navimpact/emulation/sensors.hpp"
#include "navimpact/filter/error_model.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/stochastic/simulate.hpp"

namespace navimpact::analysis {

namespace {

constexpr double kDenseRefStepS = 0.25;  // a reference this dense (with attitude) is the trajectory itself
const char* const kQuantities[4] = {"horizontal_position", "vertical_position", "velocity", "attitude"};
const char* const kUnits[4] = {"m", "m", "m/s", "rad"};
constexpr int kDof[4] = {2, 1, 3, 3};

/// Magnitude of quantity q of a nine-error vector (dp NED, dv NED, psi).
double magnitude(int q, const filter::Vector9d& e) {
  switch (q) {
    case 0: return std::hypot(e(0), e(1));
    case 1: return std::abs(e(2));
    case 2: return e.segment<3>(3).norm();
    default: return e.segment<3>(6).norm();
  }
}

double meanSquare(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return v.empty() ? NAN : s / static_cast<double>(v.size());
}

/// The trajectory of the run as the emulation's smooth truth.
emulation::SmoothTrajectory buildTrajectory(const ReplayResult& scored, const RunDiagnosisOptions& opt,
                                            std::string& source) {
  emulation::SampledTrajectory s;
  s.source = scored.cfg.rawlog;
  bool dense = scored.score && scored.score->reference.has_velocity && scored.score->reference.has_attitude &&
               scored.truth.size() >= 8;
  for (std::size_t k = 1; dense && k < scored.truth.size(); ++k)
    dense = scored.truth[k].t - scored.truth[k - 1].t <= kDenseRefStepS + 1e-9;
  std::vector<ins::NavState> x;
  if (dense) {
    x = scored.truth;
    source = "the run's reference (velocity and attitude, at most " + formatNumber(kDenseRefStepS) +
             " s apart), smoothed by P-splines";
  } else {
    ReplayConfig c = opt.replay;
    c.outages.clear();
    c.outages_every.reset();
    c.use_reference = false;
    c.record_interval_s = 0.1;
    const ReplayResult aided = runReplay(c);
    for (const auto& e : aided.run.epochs) x.push_back(e.est);
    source = "the GNSS-aided filter solution of the run without outages (the reference lacks velocity, attitude or "
             "density), every 0.1 s, smoothed by P-splines";
  }
  if (x.size() < 8) throw Error(s.source + ": too short a run to emulate its trajectory (" + std::to_string(x.size()) + " epochs)");
  s.origin = x.front().geodetic();
  Eigen::Vector3d prev = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (!s.t.empty() && !(x[k].t > s.t.back())) continue;
    s.t.push_back(x[k].t);
    s.p_L.push_back(earth::geodeticToNed(s.origin, x[k].geodetic()));
    Eigen::Vector3d rpy = x[k].rollPitchYaw();
    if (k > 0)
      for (int a = 0; a < 3; a += 2) rpy(a) = prev(a) + ins::wrapAngle(rpy(a) - prev(a));  // unwrap roll, yaw
    s.rpy.push_back(rpy);
    prev = rpy;
  }
  return emulation::SmoothTrajectory(s, emulation::SmoothingOptions{});
}

/// One realisation's outage-end errors and NEES per duration.
struct RealisationOut {
  std::vector<std::vector<filter::Vector9d>> err;  // [duration][outage]
  std::vector<std::vector<double>> nees;           // [duration][outage]
};

}  // namespace

RunDiagnosis diagnoseRun(const RunDiagnosisOptions& opt) {
  const auto wall0 = std::chrono::steady_clock::now();
  if (opt.durations_s.empty()) throw Error("diagnose --run: give at least one outage duration (--durations)");
  for (double d : opt.durations_s)
    if (!(d > 0.0) || !std::isfinite(d)) throw Error("diagnose --run: outage durations must be > 0 s, got " + formatNumber(d));
  if (!(opt.reconverge_s > 0.0)) throw Error("diagnose --run: --reconverge must be > 0 s");
  if (opt.realisations < 2) throw Error("diagnose --run: --realisations must be >= 2");
  if (!(opt.alpha > 0.0 && opt.alpha < 0.5)) throw Error("diagnose --run: --alpha must be in (0, 0.5)");
  if (opt.replay.model_spec.empty())
    throw Error("diagnose --run: give the IMU model with --model FILE[:NAME] (the model whose simulation is judged)");
  auto progress = [&](double f, const std::string& stage) {
    if (opt.progress) opt.progress(std::min(1.0, std::max(0.0, f)), stage);
  };
  const std::size_t D = opt.durations_s.size();
  // Progress: the measured replays count as 10 %, the trajectory 5 %, the simulation 85 %.

  RunDiagnosis out;
  out.rawlog = opt.replay.rawlog;
  out.realisations = opt.realisations;
  out.seed = opt.seed;
  out.alpha = opt.alpha;
  out.reconverge_s = opt.reconverge_s;

  // 1. Measured: one scored replay per duration.
  std::vector<ReplayResult> measured;
  for (std::size_t i = 0; i < D; ++i) {
    ReplayConfig c = opt.replay;
    c.outages.clear();
    c.outages_every = OutagePattern{opt.durations_s[i] + opt.reconverge_s, opt.durations_s[i]};
    progress(0.10 * double(i) / double(D), "replay");
    measured.push_back(runReplay(c));
    const ReplayResult& r = measured.back();
    if (!r.score)
      throw Error(opt.replay.rawlog + ": the rawlog has no reference (GT): a run diagnosis compares outage errors "
                                      "with a reference (import one, e.g. an RTK track)");
    if (r.score->outages.empty())
      throw Error(opt.replay.rawlog + ": no outage of " + formatNumber(opt.durations_s[i]) + " s after " +
                  formatNumber(opt.reconverge_s) + " s of GNSS fits in the run after the filter start (" +
                  formatNumber(r.aided_from_s) + " s)");
  }
  const ReplayResult& r0 = measured.front();
  out.model_source = r0.model_source;
  out.imu_rate_hz = r0.imu_rate_hz;
  out.aided_from_s = r0.aided_from_s;
  out.reference = r0.score->reference;
  out.notices = r0.notices;
  {
    const auto& ep = r0.run.epochs;
    out.run_end_s = ep.empty() ? 0.0 : ep.back().t - r0.t_zero;
  }
  const stochastic::ImuModel model = stochastic::loadImuModel(opt.replay.model_spec);

  // 2. The trajectory and the emulation span.
  progress(0.10, "trajectory");
  const emulation::SmoothTrajectory tr = buildTrajectory(r0, opt, out.trajectory_source);
  const double rate = r0.imu_rate_hz;
  const double t0 = std::max(tr.tBegin(), r0.t_zero + r0.aided_from_s);
  const auto n = static_cast<std::size_t>(std::floor((tr.tEnd() - t0) * rate + 1e-9));
  if (n < 16) throw Error(opt.replay.rawlog + ": the emulated span is too short");
  const double t1 = t0 + double(n) / rate;
  const std::vector<ins::ImuSample> perfect = emulation::perfectImu(tr, rate, t0, t1);

  // Outages of each duration in the emulation: the measured ones inside the span,
  // ends at the measured end epochs snapped to the IMU grid.
  struct SimOutage {
    std::size_t score_index;  // into measured[i].score->outages
    double t_end;             // absolute, on the IMU grid
  };
  std::vector<std::vector<SimOutage>> simOut(D);
  std::vector<NavRunOptions> navs(D);
  std::vector<TruthSeries> truths(D);
  for (std::size_t i = 0; i < D; ++i) {
    const auto& sc = *measured[i].score;
    const double tz = measured[i].t_zero;
    NavRunOptions nav = measured[i].nav;
    nav.outages.clear();
    nav.reference_lever_B = Eigen::Vector3d::Zero();  // the emulation's truth is the IMU point
    for (std::size_t q = 0; q < sc.outages.size(); ++q) {
      const auto& o = sc.outages[q];
      const double a = o.start_s + tz, b = a + o.duration_s;
      if (a < t0 + 1.0 || b > t1) continue;
      const double ke = std::floor((o.end_s + tz - t0) * rate + 0.5);
      const double te = t0 + ke / rate;
      if (!(te > a) || te > t1) continue;
      nav.outages.push_back({a, b});
      simOut[i].push_back({q, te});
      truths[i].t.push_back(te);
      truths[i].x.push_back(emulation::truthNavState(tr, te));
    }
    if (simOut[i].empty())
      throw Error(opt.replay.rawlog + ": no outage of " + formatNumber(opt.durations_s[i]) +
                  " s falls inside the emulated span");
    navs[i] = nav;
  }
  const ins::NavState truth0 = emulation::truthNavState(tr, t0);
  filter::Vector9d sigma0 = r0.nav.P0_nav.diagonal().cwiseSqrt();

  // Static recording (optional), loaded once.
  std::optional<ImuSeries> rec;
  if (!opt.static_file.empty()) {
    rec = readImuCsv(opt.static_file, opt.static_csv);
    out.errors_source = "windows of the static recording " + opt.static_file + " (start drawn per realisation)";
  } else {
    out.errors_source = "simulated from the model " + r0.model_source;
  }

  // Antenna, GNSS and barometer of the emulation: the run's own fix times and covariances.
  const Eigen::Vector3d lever = r0.nav.lever_arm_B;
  const std::vector<GnssFix>& realGnss = r0.gnss;
  const std::vector<BaroSample>& realBaro = r0.baro;

  // 3. Simulated realisations.
  const int R = opt.realisations;
  std::vector<RealisationOut> sims(R);
  std::atomic<int> next{0}, done{0};
  std::mutex mu;
  std::string first_error;
  auto work = [&]() {
    for (;;) {
      const int r = next++;
      if (r >= R) return;
      try {
        const std::uint64_t seed = stochastic::deriveSeed(opt.seed, static_cast<std::uint64_t>(r));
        std::array<std::vector<double>, 6> err;
        if (rec) {
          emulation::StaticRecordingSpec spec;
          spec.file = opt.static_file;
          spec.seed = stochastic::deriveSeed(seed, 4);
          err = emulation::staticImuErrors(*rec, spec, rate, n).axis;
        } else {
          err = emulation::modelImuErrors(model, rate, n, stochastic::deriveSeed(seed, 0)).axis;
        }
        EmulatedRun run = emulateRun(perfect, err, tr, t0, t1, emulation::GnssOptions{}, emulation::BaroOptions{},
                                     truth0, sigma0, seed);
        // GNSS and baro at the run's own epochs with its own sigmas.
        run.gnss.clear();
        run.baro.clear();
        const auto zg = emulation::standardNormal(6 * realGnss.size() + 1, stochastic::deriveSeed(seed, 5));
        for (std::size_t k = 0; k < realGnss.size(); ++k) {
          const GnssFix& f = realGnss[k];
          if (f.t < t0 || f.t > t1) continue;
          const emulation::TruthState s = tr.at(f.t);
          const Eigen::Matrix3d Lp = f.cov_pos_N->llt().matrixL();
          const Eigen::Vector3d np(zg[6 * k], zg[6 * k + 1], zg[6 * k + 2]);
          GnssFix g;
          g.t = f.t;
          g.pos = earth::nedToGeodetic(tr.origin(), s.p_L + s.C_BtoN * lever + Lp * np);
          g.cov_pos_N = f.cov_pos_N;
          if (f.v_N && f.cov_vel_N) {
            const Eigen::Matrix3d Lv = f.cov_vel_N->llt().matrixL();
            const Eigen::Vector3d nv(zg[6 * k + 3], zg[6 * k + 4], zg[6 * k + 5]);
            g.v_N = s.v_N + s.C_BtoN * s.w_NB_B.cross(lever) + Lv * nv;
            g.cov_vel_N = f.cov_vel_N;
          }
          run.gnss.push_back(g);
        }
        const auto zb = emulation::standardNormal(realBaro.size() + 1, stochastic::deriveSeed(seed, 6));
        for (std::size_t k = 0; k < realBaro.size(); ++k) {
          const BaroSample& b = realBaro[k];
          if (b.t < t0 || b.t > t1 || !b.sigma_m) continue;
          BaroSample o = b;
          o.h = tr.at(b.t).pos.h + *b.sigma_m * zb[k];
          run.baro.push_back(o);
        }
        RealisationOut& ro = sims[r];
        ro.err.resize(D);
        ro.nees.resize(D);
        for (std::size_t i = 0; i < D; ++i) {
          const NavRunResult res = runNav(run.input(truths[i]), model, navs[i]);
          if (res.epochs.size() != simOut[i].size())
            throw Error("diagnose --run: realisation " + std::to_string(r) + " recorded " +
                        std::to_string(res.epochs.size()) + " outage ends, expected " + std::to_string(simOut[i].size()));
          for (const auto& e : res.epochs) {
            ro.err[i].push_back(e.err);
            ro.nees[i].push_back(e.nees[0]);
          }
          const int dn = ++done;
          std::lock_guard<std::mutex> lk(mu);
          progress(0.15 + 0.85 * double(dn) / double(R * D), "simulation");
        }
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lk(mu);
        if (first_error.empty()) first_error = e.what();
        next = R;
      }
    }
  };
  int threads = opt.threads > 0 ? opt.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = std::min(threads, R);
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (!first_error.empty()) throw Error(first_error);

  // 4. Comparisons and NEES bands.
  const ReferenceInfo& ref = out.reference;
  const bool has[4] = {true, true, ref.has_velocity, ref.has_attitude};
  std::size_t m = 0;
  for (std::size_t i = 0; i < D; ++i) m += 1 + (has[2] ? 1 : 0) + (has[3] ? 1 : 0) + 2;
  out.tests = m;
  out.test_level = opt.alpha / double(m);
  const double a = out.test_level;
  for (std::size_t i = 0; i < D; ++i) {
    const ReplayResult& mr = measured[i];
    const RunScore& sc = *mr.score;
    DurationDiagnosis dd;
    dd.duration_s = opt.durations_s[i];
    dd.period_s = opt.durations_s[i] + opt.reconverge_s;
    // the measured outages the emulation also has
    for (const auto& so : simOut[i]) dd.measured.push_back(sc.outages[so.score_index]);
    dd.distribution = sc.distribution;
    const std::size_t K = dd.measured.size();
    double sn = 0.0;
    for (const auto& o : dd.measured) sn += o.nees;
    dd.anees = sn / double(K);
    boost::math::chi_squared chi(3.0 * double(K));
    dd.anees_lo = boost::math::quantile(chi, a / 2) / double(K);
    dd.anees_hi = boost::math::quantile(chi, 1 - a / 2) / double(K);
    dd.anees_rejects = dd.anees < dd.anees_lo || dd.anees > dd.anees_hi;
    double ps = 0.0;
    std::size_t pn = 0;
    for (const auto& s : sims)
      for (double v : s.nees[i])
        if (std::isfinite(v)) {
          ps += v;
          ++pn;
        }
    dd.predicted_anees = pn ? ps / double(pn) : NAN;
    dd.simulated_outages = static_cast<std::size_t>(R) * simOut[i].size();
    if (dd.anees_rejects)
      out.reasons.push_back("measured mean NEES " + formatNumber(dd.anees, 3) + " at " + formatNumber(dd.duration_s) +
                            " s outages outside its band [" + formatNumber(dd.anees_lo, 3) + ", " +
                            formatNumber(dd.anees_hi, 3) + "]");

    // measured errors: the end epoch of each run outage (velocity, attitude from the run's epochs)
    std::vector<filter::Vector9d> mErr;
    for (const auto& so : simOut[i]) {
      const OutageScore& o = sc.outages[so.score_index];
      filter::Vector9d e = filter::Vector9d::Constant(NAN);
      e.head<3>() = o.err_N;
      for (const auto& ro : mr.run.outages) {
        if (std::abs(ro.window.start_s - mr.t_zero - o.start_s) > 1e-6 || ro.end_epoch < 0) continue;
        const auto& ep = mr.run.epochs[static_cast<std::size_t>(ro.end_epoch)];
        e.tail<6>() = ep.err.tail<6>();
      }
      mErr.push_back(e);
    }
    for (int q = 0; q < 4; ++q) {
      if (!has[q]) continue;
      QuantityComparison c;
      c.quantity = kQuantities[q];
      c.unit = kUnits[q];
      c.duration_s = dd.duration_s;
      c.dof = kDof[q];
      for (const auto& e : mErr) c.measured.push_back(magnitude(q, e));
      for (const auto& s : sims)
        for (const auto& e : s.err[i]) c.predicted.push_back(magnitude(q, e));
      const double refVar = q == 0 ? 2 * ref.sigma_h_m * ref.sigma_h_m : q == 1 ? ref.sigma_v_m * ref.sigma_v_m : 0.0;
      const double msM = meanSquare(c.measured), msP = meanSquare(c.predicted) + refVar;
      c.measured_rms = std::sqrt(msM);
      c.predicted_rms = std::sqrt(msP);
      c.predicted_p05 = percentile(c.predicted, 0.05);
      c.predicted_p50 = percentile(c.predicted, 0.50);
      c.predicted_p95 = percentile(c.predicted, 0.95);
      c.ratio = c.measured_rms / c.predicted_rms;
      const double d1 = double(c.dof) * double(c.measured.size()), d2 = double(c.dof) * double(c.predicted.size());
      boost::math::fisher_f F(d1, d2);
      const double f = msM / msP;
      if (std::isfinite(f) && f > 0.0) {
        const double cdf = boost::math::cdf(F, f);
        c.p_value = std::min(1.0, 2.0 * std::min(cdf, 1.0 - cdf));
        c.ratio_lo = std::sqrt(f / boost::math::quantile(F, 1 - a / 2));
        c.ratio_hi = std::sqrt(f / boost::math::quantile(F, a / 2));
      } else {
        c.p_value = f == 0.0 ? 0.0 : 1.0;
        c.ratio_lo = c.ratio_hi = c.ratio;
      }
      c.rejects = c.p_value < a;
      if (c.rejects)
        out.reasons.push_back(c.quantity + " at " + formatNumber(c.duration_s) + " s outages: measured/predicted RMS " +
                              formatNumber(c.ratio, 3) + " [" + formatNumber(c.ratio_lo, 3) + ", " +
                              formatNumber(c.ratio_hi, 3) + "], p = " + formatNumber(c.p_value, 3));
      out.comparisons.push_back(std::move(c));
    }
    out.durations.push_back(std::move(dd));
  }
  out.verdict = out.reasons.empty() ? "adequate" : "inadequate";
  progress(1.0, "done");
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return out;
}

}  // namespace navimpact::analysis
