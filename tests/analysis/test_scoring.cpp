// Scoring a run against a reference: the percentile, the GNSS-aided RMS, and
// the NEES / coverage statistics on errors drawn from the predicted covariance
// plus the reference's (they must pass) and from an inflated one (they must
// fail). Draws are seeded and the seed and parameters printed.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <cmath>
#include <cstdio>
#include <random>

#include "navimpact/analysis/scoring.hpp"
#include "navimpact/core/error.hpp"

namespace an = navimpact::analysis;
using Eigen::Matrix3d;
using Eigen::Vector3d;

TEST(Scoring, PercentileType7) {
  EXPECT_DOUBLE_EQ(an::percentile({3.0, 1.0, 2.0}, 0.5), 2.0);
  EXPECT_DOUBLE_EQ(an::percentile({1.0, 2.0, 3.0, 4.0}, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(an::percentile({0.0, 10.0}, 0.95), 9.5);
  EXPECT_TRUE(std::isnan(an::percentile({}, 0.5)));
}

namespace {

/// A run of K outages, each ending at a reference epoch with position error
/// drawn from N(0, scale^2 (P + R_ref)), P random (correlated, 0.1-30 m);
/// epochs outside the outages carry a fixed known error.
an::NavRunResult syntheticRun(int K, double scale, double ref_h, double ref_v, std::mt19937_64& rng) {
  std::normal_distribution<double> N01;
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  an::NavRunResult run;
  run.has_truth = true;
  double t = 0.0;
  for (int k = 0; k < K; ++k) {
    // two aided epochs with errors (3, 4, 2) m, velocity 0.5 m/s on N, psi 1 mrad on D
    for (int j = 0; j < 2; ++j) {
      an::NavEpoch e;
      e.t = t;
      e.err.setZero();
      e.err.head<3>() = Vector3d(3.0, 4.0, 2.0);
      e.err[3] = 0.5;
      e.err[8] = 1e-3;
      e.P_pos = Matrix3d::Identity();
      run.epochs.push_back(e);
      t += 1.0;
    }
    an::OutageSummary o;
    o.window = {t - 1.0, t + 10.0};
    // one epoch inside the outage, then its end
    an::NavEpoch mid;
    mid.t = t + 5.0;
    mid.err.setZero();
    mid.err.head<3>() = Vector3d(100.0, 0.0, -50.0);
    mid.P_pos = Matrix3d::Identity();
    run.epochs.push_back(mid);
    an::NavEpoch e;
    e.t = t + 10.0;
    Eigen::Matrix3d A;
    for (int i = 0; i < 9; ++i) A(i / 3, i % 3) = U(rng);
    const Vector3d s(std::exp(std::log(0.1) + (std::log(30.0) - std::log(0.1)) * 0.5 * (1 + U(rng))),
                     std::exp(std::log(0.1) + (std::log(30.0) - std::log(0.1)) * 0.5 * (1 + U(rng))),
                     std::exp(std::log(0.1) + (std::log(30.0) - std::log(0.1)) * 0.5 * (1 + U(rng))));
    e.P_pos = s.asDiagonal() * (Matrix3d::Identity() + 0.3 * (A + A.transpose()) / 2.0 * 0.5) * s.asDiagonal();
    e.P_pos = 0.5 * (e.P_pos + e.P_pos.transpose()).eval();
    Eigen::SelfAdjointEigenSolver<Matrix3d> es(e.P_pos);
    if (es.eigenvalues().minCoeff() <= 0.0) e.P_pos = s.cwiseAbs2().asDiagonal();
    const Matrix3d S = e.P_pos + Vector3d(ref_h * ref_h, ref_h * ref_h, ref_v * ref_v).asDiagonal().toDenseMatrix();
    const Matrix3d L = S.llt().matrixL();
    e.err.setZero();
    e.err.head<3>() = scale * (L * Vector3d(N01(rng), N01(rng), N01(rng)));
    run.epochs.push_back(e);
    o.end_epoch = static_cast<int>(run.epochs.size()) - 1;
    run.outages.push_back(o);
    t += 11.0;
  }
  return run;
}

}  // namespace

TEST(Scoring, AidedRmsLeavesOutagesOut) {
  std::mt19937_64 rng(1);
  const an::NavRunResult run = syntheticRun(3, 1.0, 0.0, 0.0, rng);
  const an::RunScore s = an::scoreRun(run, 0.0, 0.0, {});
  EXPECT_EQ(s.aided_epochs, 6u);
  EXPECT_NEAR(s.horizontal_rms_m, 5.0, 1e-12);
  EXPECT_NEAR(s.vertical_rms_m, 2.0, 1e-12);
  EXPECT_NEAR(s.velocity_rms_mps, 0.5, 1e-12);
  EXPECT_NEAR(s.attitude_rms_rad[2], 1e-3, 1e-15);
  ASSERT_EQ(s.outages.size(), 3u);
  EXPECT_NEAR(s.outages[0].max_drift_h_m, std::max(100.0, s.outages[0].horizontal_error_m), 1e-9);
  EXPECT_NEAR(s.outages[0].duration_s, 11.0, 1e-12);
  // aided_from after everything: no aided epochs
  EXPECT_EQ(an::scoreRun(run, 0.0, 1e9, {}).aided_epochs, 0u);
  an::ReferenceInfo noVel;
  noVel.has_velocity = noVel.has_attitude = false;
  EXPECT_TRUE(std::isnan(an::scoreRun(run, 0.0, 0.0, noVel).velocity_rms_mps));
  an::NavRunResult noTruth = run;
  noTruth.has_truth = false;
  EXPECT_THROW(an::scoreRun(noTruth, 0.0, 0.0, {}), navimpact::Error);
}

// Errors drawn from the prediction plus the reference's sigma (0-2 m, 0-4 m,
// drawn): mean NEES inside its chi2_3K / K band, per-outage NEES in band
// ~95 %, coverage at the Gaussian levels (binomial 4-sigma bands). Errors
// 1.5x too large: the mean NEES is above the band, the 1-sigma coverage too low.
TEST(Scoring, NeesAndCoverageAcceptTheRightSigmaAndRejectAWrongOne) {
  const std::uint64_t seed = 90210;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const int K = 400;
  const double ref_h = 2.0 * U(rng), ref_v = 4.0 * U(rng);
  std::printf("seed %llu: %d outages, reference sigma %.3f m horizontal, %.3f m vertical\n",
              static_cast<unsigned long long>(seed), K, ref_h, ref_v);
  an::ReferenceInfo ref;
  ref.sigma_h_m = ref_h;
  ref.sigma_v_m = ref_v;
  const an::RunScore good = an::scoreRun(syntheticRun(K, 1.0, ref_h, ref_v, rng), 0.0, 0.0, ref);
  const auto& d = good.distribution;
  std::printf("  right sigma: mean NEES %.3f (band %.3f..%.3f), coverage %.3f %.3f %.3f, in band %zu\n",
              d.mean_nees, d.mean_nees_lo, d.mean_nees_hi, d.coverage[0], d.coverage[1], d.coverage[2],
              d.nees_in_band);
  EXPECT_EQ(d.count, std::size_t(K));
  EXPECT_GE(d.mean_nees, d.mean_nees_lo);
  EXPECT_LE(d.mean_nees, d.mean_nees_hi);
  EXPECT_NEAR(d.nees_band_lo, 0.2158, 1e-3);
  EXPECT_NEAR(d.nees_band_hi, 9.348, 1e-3);
  EXPECT_NEAR(double(d.nees_in_band) / K, 0.95, 4.0 * std::sqrt(0.95 * 0.05 / K));
  for (int k = 0; k < 3; ++k) {
    const double p = d.coverage_expected[k];
    // 3K per-axis values, correlated within an outage: band for K independent draws
    EXPECT_NEAR(d.coverage[k], p, 4.0 * std::sqrt(p * (1 - p) / K) + 1e-3) << k + 1 << " sigma";
  }
  EXPECT_LE(d.median_h_m, d.p95_h_m);
  const an::RunScore bad = an::scoreRun(syntheticRun(K, 1.5, ref_h, ref_v, rng), 0.0, 0.0, ref);
  const auto& b = bad.distribution;
  std::printf("  1.5x errors: mean NEES %.3f (band %.3f..%.3f), coverage %.3f %.3f %.3f\n", b.mean_nees,
              b.mean_nees_lo, b.mean_nees_hi, b.coverage[0], b.coverage[1], b.coverage[2]);
  EXPECT_GT(b.mean_nees, b.mean_nees_hi);
  EXPECT_LT(b.coverage[0], b.coverage_expected[0] - 4.0 * std::sqrt(0.68 * 0.32 / K));
}
