// Error-state EKF: structured covariance propagation, Joseph-form updates,
// closed-loop feedback. Equation numbers: Groves 2013 ch. 3 and 14.
#include "navimpact/filter/ekf.hpp"
#include "navimpact/filter/model_entry.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <boost/math/distributions/chi_squared.hpp>
#include <unsupported/Eigen/MatrixFunctions>

#include <array>
#include <cmath>
#include <functional>
#include <sstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "nine_row_product.hpp"

namespace navimpact::filter {

using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;
using ins::skew;
using detail::nineRowProduct;

Discretization parseDiscretization(const std::string& s) {
  if (s == "series") return Discretization::Series;
  if (s == "vanloan") return Discretization::VanLoan;
  throw Error("unknown discretization '" + s + "' (expected 'series' or 'vanloan')");
}

/// Structured transition Phi = [A B; 0 D] (D block-diagonal over process
/// blocks) and the discrete process noise Q (full).
struct ErrorStateEkf::Transition {
  Matrix9d A;
  MatrixXd B, D, Q;
  /// D and the IMU block of Q hold the exact blocks of this interval length
  /// (they depend on dt only); -1: not filled, or Q overwritten whole (Van Loan).
  double imu_dt = -1.0;
};

struct ErrorStateEkf::Cache {
  /// Exact discrete IMU-error blocks (from stochastic) for one interval length.
  struct Blocks {
    double dt = -1.0;
    std::vector<MatrixXd> Phi, Qd;  // per process block
  };
  std::vector<Blocks> blocks;       // a few interval lengths (sample, k samples, ...)
  std::size_t next_slot = 0;
  const Blocks& blocksFor(const std::vector<ProcessBlock>& layout_blocks, double dt);
  // covariance-only propagation along an unchanged nominal
  bool nominal_valid = false;
  ins::NavState nominal;
  Vector3d w, f;
  double nominal_dt = 0.0;
  Transition T;
  Transition tmp;                   // scratch
  MatrixXd Fni, FniFii, FniQii, FniQiiFii, FniFiiQii, Qni;  // scratch of the series form
  /// per IMU state of a multi-state block: h F, h Qc, h Qc F', h F Qc (its column)
  std::vector<std::array<double, 4>> rows_of;
  MatrixXd Mni;                     // scratch of the propagation
  MatrixXd PHt, K, KS, Pc;          // scratch of the update (KS holds K L)
  VectorXd inv;
};

/// The cached exact IMU-error blocks for @p dt (relative tolerance 1e-9, far
/// below any effect on the covariance: Phi = exp(-dt/T) changes by 1e-9 dt/T).
const ErrorStateEkf::Cache::Blocks& ErrorStateEkf::Cache::blocksFor(
    const std::vector<ProcessBlock>& layout_blocks, double dt) {
  for (const Blocks& b : blocks)
    if (std::abs(b.dt - dt) <= 1e-9 * dt) return b;
  constexpr std::size_t kSlots = 4;
  Blocks* e = nullptr;
  if (blocks.size() < kSlots) {
    blocks.emplace_back();
    e = &blocks.back();
  } else {
    e = &blocks[next_slot];
    next_slot = (next_slot + 1) % kSlots;
  }
  e->Phi.clear();
  e->Qd.clear();
  for (const ProcessBlock& b : layout_blocks) {
    const bool constant = b.ss.F.cwiseAbs().maxCoeff() == 0.0 && b.ss.Qc.cwiseAbs().maxCoeff() == 0.0;
    e->Phi.push_back(constant ? MatrixXd::Identity(b.ss.n, b.ss.n) : b.ss.Phi(dt));
    e->Qd.push_back(constant ? MatrixXd::Zero(b.ss.n, b.ss.n) : b.ss.Qd(dt));
  }
  e->dt = dt;
  return *e;
}

namespace {
/// @throws Error "WHAT must be > 0 at t = T s" unless every sigma is finite and > 0.
template <class Derived>
void requirePositiveSigma(const Eigen::MatrixBase<Derived>& sigma, const char* what, double t) {
  if (!(sigma.array() > 0.0).all() || !sigma.allFinite())
    throw Error(std::string(what) + " must be > 0 at t = " + formatNumber(t, 9) + " s");
}
void requirePositiveSigma(double sigma, const char* what, double t) {
  requirePositiveSigma(Eigen::Matrix<double, 1, 1>(sigma), what, t);
}

bool sameState(const ins::NavState& a, const ins::NavState& b) {
  return a.lat == b.lat && a.lon == b.lon && a.h == b.h && a.v_N == b.v_N &&
         a.q_BtoN.coeffs() == b.q_BtoN.coeffs();
}
}  // namespace

ImuErrorOptions effectiveImuOptions(const stochastic::ImuModel& model, const EkfConfig& cfg) {
  ImuErrorOptions o = cfg.imu;
  if (model.rate_hz > 0.0)
    o.white_gm_below_s = std::max(o.white_gm_below_s, cfg.propagate_every / model.rate_hz);
  return o;
}

ErrorStateEkf::ErrorStateEkf(const ins::NavState& x0, const Matrix9d& P0_nav,
                             const stochastic::ImuModel& model, const EkfConfig& cfg)
    : cfg_(cfg), mech_(x0, cfg.mechanization), cache_(std::make_shared<Cache>()) {
  if (cfg.propagate_every < 1)
    throw Error("propagate_every must be >= 1, got " + std::to_string(cfg.propagate_every));
  if (!(cfg.gate_probability == 0.0 ||
        (cfg.gate_probability >= kMinGateProbability && cfg.gate_probability < 1.0)))
    throw Error("gate_probability must be 0 (gate off) or in [" + formatNumber(kMinGateProbability, 3) +
                ", 1), got " + formatNumber(cfg.gate_probability, 9));
  if (cfg.gate_readmit_after < 0 || cfg.gate_readmit_after > 1000)
    throw Error("gate_readmit_after must be in 0..1000 (0 = never), got " + std::to_string(cfg.gate_readmit_after));
  if (!P0_nav.allFinite() || (P0_nav - P0_nav.transpose()).cwiseAbs().maxCoeff() >
                                 1e-12 * (1.0 + P0_nav.cwiseAbs().maxCoeff()) ||
      (P0_nav.diagonal().array() < 0.0).any())
    throw Error("initial navigation covariance must be finite, symmetric, with diagonal >= 0");
  layout_ = layoutFor(model, cfg).layout;  // the one model-entry path (model_entry.hpp)
  const int N = layout_.size(), m = layout_.imuSize();
  P_ = MatrixXd::Zero(N, N);
  P_.topLeftCorner<9, 9>() = P0_nav;
  P_.bottomRightCorner(m, m) = layout_.imuP0();
  x_imu_ = VectorXd::Zero(m);
  {
    // initial estimates of the extra states (prior means; zero by default)
    const ExtraStates& e = cfg.imu.extra;
    auto set3 = [&](Extra g, const Vector3d& v) {
      if (const int k = layout_.extraIndex(g); k >= 0) x_imu_.segment<3>(k - kNav) = v;
    };
    set3(Extra::GyroScale, e.gyro_scale0);
    set3(Extra::AccScale, e.acc_scale0);
    set3(Extra::GyroMisalignment, e.gyro_misalignment0_rad);
    set3(Extra::AccMisalignment, e.acc_misalignment0_rad);
    set3(Extra::LeverArm, e.lever_arm_error0_m);
    if (const int k = layout_.extraIndex(Extra::TimeOffset); k >= 0) x_imu_(k - kNav) = e.time_offset0_s;
    if (!x_imu_.allFinite()) throw Error("initial estimates of the extra states must be finite");
  }
  A_acc_.setIdentity();
  B_acc_ = MatrixXd::Zero(9, m);
  D_acc_ = MatrixXd::Identity(m, m);
  Q_acc_ = MatrixXd::Zero(N, N);
  last_.t = x0.t;
  // variance floors of the positive-definiteness check (PdCheck)
  floor_.resize(N);
  floor_.segment<3>(kPos).setConstant(PdCheck::position_floor_m2);
  floor_.segment<3>(kVel).setConstant(PdCheck::velocity_floor_m2ps2);
  floor_.segment<3>(kAtt).setConstant(PdCheck::attitude_floor_rad2);
  VectorXd natural = P_.diagonal().tail(m);
  for (const ProcessBlock& b : layout_.blocks())
    for (int j = 0; j < b.ss.n; ++j)
      natural(b.offset - kNav + j) = std::max(natural(b.offset - kNav + j), b.ss.Qc(j, j) * 1.0 /* s */);
  for (int i = 0; i < m; ++i) floor_(kNav + i) = std::max(PdCheck::imu_floor_relative * natural(i), 1e-300);
}

Eigen::Matrix<double, 6, 1> ErrorStateEkf::sensorErrors() const {
  Eigen::Matrix<double, 6, 1> e;
  for (int c = 0; c < 6; ++c) e(c) = layout_.sensorRow(c).dot(x_imu_);
  return e;
}

void ErrorStateEkf::setImuStates(const VectorXd& x) {
  if (x.size() != layout_.imuSize() || !x.allFinite())
    throw Error("IMU states: expected " + std::to_string(layout_.imuSize()) + " finite values, got " +
                std::to_string(x.size()));
  x_imu_ = x;
  cache_->nominal_valid = false;
}

double ErrorStateEkf::extra(Extra g, int i) const {
  const int k = layout_.extraIndex(g);
  return k < 0 ? 0.0 : x_imu_(k - kNav + i);
}

namespace {
SensorParams paramsFrom(const StateLayout& L, const std::function<double(int)>& v) {
  SensorParams p;
  auto get3 = [&](Extra g, Eigen::Vector3d& out) {
    const int k = L.extraIndex(g);
    if (k >= 0) out = Vector3d(v(k), v(k + 1), v(k + 2));
  };
  get3(Extra::GyroScale, p.gyro_scale);
  get3(Extra::AccScale, p.acc_scale);
  get3(Extra::GyroMisalignment, p.gyro_misalignment_rad);
  get3(Extra::AccMisalignment, p.acc_misalignment_rad);
  get3(Extra::LeverArm, p.lever_arm_error_B_m);
  const int k = L.extraIndex(Extra::TimeOffset);
  if (k >= 0) p.time_offset_s = v(k);
  return p;
}
}  // namespace

SensorParams ErrorStateEkf::extraEstimates() const {
  return paramsFrom(layout_, [&](int k) { return x_imu_(k - kNav); });
}

SensorParams ErrorStateEkf::extraSigmas() const {
  return paramsFrom(layout_, [&](int k) { return std::sqrt(std::max(P_(k, k), 0.0)); });
}

Vector9d ErrorStateEkf::stateRate() const {
  const ins::NavState& x = state();
  const Vector3d w_IN_N = earth::w_IE_N(x.lat) + earth::w_EN_N(x.lat, x.h, x.v_N);
  Vector9d r;
  r << x.v_N, accelerationN(), x.C_BtoN() * w_IB_B_ - w_IN_N;  // C w_NB_B
  return r;
}

double ErrorStateEkf::timeOffsetEstimate() const { return extra(Extra::TimeOffset); }

Vector9d ErrorStateEkf::carry(double tau) const { return stateRate() * tau; }

Matrix9d ErrorStateEkf::navCovarianceOnTrueClock() const {
  const Matrix9d Pnn = P_.topLeftCorner<9, 9>();
  const int k = layout_.extraIndex(Extra::TimeOffset);
  if (k < 0) return Pnn;
  // e = dx_nav + J dd, dd = d_est - d (the same J as carryInitialStateToImuClock's, sign for sign)
  const Vector9d J = stateRate();
  const Vector9d Pnk = P_.block<9, 1>(0, k);
  Matrix9d Pt = Pnn + J * Pnk.transpose() + Pnk * J.transpose() + P_(k, k) * J * J.transpose();
  return 0.5 * (Pt + Pt.transpose());
}

void ErrorStateEkf::addExtraCouplings(const Lin& L, Eigen::Ref<MatrixXd> X, int col0) const {
  // corrected - true = -diag(true) ds + [true x] dm (state_layout.hpp), entering
  // d(psi)/dt and d(dv)/dt through C_BtoN (Groves 14.64-14.65)
  const int gs = layout_.extraIndex(Extra::GyroScale), as = layout_.extraIndex(Extra::AccScale);
  const int gm = layout_.extraIndex(Extra::GyroMisalignment), am = layout_.extraIndex(Extra::AccMisalignment);
  if (gs >= 0) X.block<3, 3>(kAtt, gs - col0) = -L.CDw;
  if (gm >= 0) X.block<3, 3>(kAtt, gm - col0) = L.CSw;
  if (as >= 0) X.block<3, 3>(kVel, as - col0) = -L.CDf;
  if (am >= 0) X.block<3, 3>(kVel, am - col0) = L.CSf;
}

ErrorStateEkf::Lin ErrorStateEkf::currentLin() const {
  Lin L;
  L.Fnn = navErrorDynamics(state(), f_B_);
  L.C = state().C_BtoN();
  const auto& psd = layout_.whitePsd();
  const Vector3d pg(psd[0], psd[1], psd[2]), pa(psd[3], psd[4], psd[5]);
  L.Qv = L.C * pa.asDiagonal() * L.C.transpose();
  L.Qa = L.C * pg.asDiagonal() * L.C.transpose();
  if (layout_.hasExtra()) {
    L.CDw = L.C * w_IB_B_.asDiagonal();
    L.CSw = L.C * skew(w_IB_B_);
    L.CDf = L.C * f_B_.asDiagonal();
    L.CSf = L.C * skew(f_B_);
  }
  return L;
}

MatrixXd ErrorStateEkf::assembleF(const Lin& L) const {
  const int N = size();
  MatrixXd F = MatrixXd::Zero(N, N);
  F.topLeftCorner<9, 9>() = L.Fnn;
  for (const ProcessBlock& b : layout_.blocks()) {
    const int row = b.channel < 3 ? kAtt : kVel;
    // d(psi)/dt += C dw_B, d(dv)/dt += C df_B, with dsensor = -H dx_imu (Groves 14.64-14.65)
    F.block(row, b.offset, 3, b.ss.n) = -L.C.col(b.channel % 3) * b.ss.H;
    F.block(b.offset, b.offset, b.ss.n, b.ss.n) = b.ss.F;
  }
  if (layout_.hasExtra()) addExtraCouplings(L, F, 0);
  return F;
}

MatrixXd ErrorStateEkf::assembleQc(const Lin& L) const {
  const int N = size();
  MatrixXd Q = MatrixXd::Zero(N, N);
  Q.block<3, 3>(kVel, kVel) = L.Qv;
  Q.block<3, 3>(kAtt, kAtt) = L.Qa;
  for (const ProcessBlock& b : layout_.blocks())
    Q.block(b.offset, b.offset, b.ss.n, b.ss.n) = b.ss.Qc;
  return Q;
}

MatrixXd ErrorStateEkf::F() const { return assembleF(currentLin()); }

MatrixXd ErrorStateEkf::Qc() const { return assembleQc(currentLin()); }

void ErrorStateEkf::buildTransition(const Lin& L, double dt, Transition& T) const {
  const int m = layout_.imuSize();
  const auto& blocks = layout_.blocks();
  Cache& c = *cache_;
  const Cache::Blocks& cb = c.blocksFor(blocks, dt);
  // D and the IMU block of Q: the exact blocks of cb, written once per interval
  // length (the navigation rows and columns of Q are overwritten below)
  if (T.imu_dt != cb.dt || T.D.rows() != m || T.Q.rows() != 9 + m) {
    T.D.setZero(m, m);
    T.Q.setZero(9 + m, 9 + m);
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      const int o = blocks[k].offset - kNav, n = blocks[k].ss.n;
      T.D.block(o, o, n, n) = cb.Phi[k];
      T.Q.block(9 + o, 9 + o, n, n) = cb.Qd[k];
    }
    T.imu_dt = cb.dt;
  }

  if (cfg_.discretization == Discretization::VanLoan) {
    // Van Loan (1978): expm([-F Qc; 0 F'] dt) = [.. Phi^-1 Qd; 0 Phi'] (Groves 3.? / 14.?)
    const MatrixXd F = assembleF(L), Q = assembleQc(L);
    const int N = size();
    MatrixXd M = MatrixXd::Zero(2 * N, 2 * N);
    M.topLeftCorner(N, N) = -F * dt;
    M.topRightCorner(N, N) = Q * dt;
    M.bottomRightCorner(N, N) = F.transpose() * dt;
    const MatrixXd E = M.exp();
    const MatrixXd Phi = E.bottomRightCorner(N, N).transpose();
    MatrixXd Qd = Phi * E.topRightCorner(N, N);
    Qd = 0.5 * (Qd + Qd.transpose());
    T.A = Phi.topLeftCorner<9, 9>();
    T.B = Phi.topRightCorner(9, m);
    // IMU-error blocks keep their exact closed forms (identical up to rounding)
    const MatrixXd Qii = T.Q.bottomRightCorner(m, m);
    T.Q = Qd;
    T.Q.bottomRightCorner(m, m) = Qii;
    T.imu_dt = -1.0;  // Q overwritten whole
    return;
  }

  // Series form (Groves 3.34, 3.46-3.47 truncated): Phi to second order in dt,
  // Qd to third order, computed block by block; no heap allocation once the
  // scratch matrices have their size.
  const Matrix9d& Fnn = L.Fnn;
  const Eigen::Matrix3d& C = L.C;
  MatrixXd& Fni = c.Fni;
  MatrixXd& FniFii = c.FniFii;
  MatrixXd& FniQii = c.FniQii;
  MatrixXd& FniQiiFii = c.FniQiiFii;
  MatrixXd& FniFiiQii = c.FniFiiQii;
  // every call writes the same entries below (the layout's), the rest stays zero
  if (Fni.rows() != 9 || Fni.cols() != m)
    for (MatrixXd* M : {&Fni, &FniFii, &FniQii, &FniQiiFii, &FniFiiQii}) M->setZero(9, m);
  for (const ProcessBlock& b : blocks) {
    const int o = b.offset - kNav, n = b.ss.n;
    const int row = b.channel < 3 ? kAtt : kVel;
    const Vector3d col = -C.col(b.channel % 3);
    if (n == 1) {  // GM, RW, turn-on bias: scalar block, no temporaries
      const double h = b.ss.H(0), f = b.ss.F(0, 0), q = b.ss.Qc(0, 0);
      Fni.block<3, 1>(row, o) = col * h;
      FniFii.block<3, 1>(row, o) = col * (h * f);
      FniQii.block<3, 1>(row, o) = col * (h * q);
      FniQiiFii.block<3, 1>(row, o) = col * (h * q * f);
      FniFiiQii.block<3, 1>(row, o) = col * (h * f * q);
      continue;
    }
    // multi-state block (DR, SIN): (3 x 1) column times (1 x n) rows, n small;
    // the rows h F, h Qc, h Qc F', h F Qc of the block's constant model, once
    if (c.rows_of.size() != static_cast<std::size_t>(m)) {
      c.rows_of.assign(m, {});
      for (const ProcessBlock& bb : blocks) {
        if (bb.ss.n == 1) continue;
        for (int j = 0; j < bb.ss.n; ++j) {
          const double hF = bb.ss.H.dot(bb.ss.F.col(j)), hQ = bb.ss.H.dot(bb.ss.Qc.col(j));
          double hQFt = 0.0, hFQ = 0.0;
          for (int i = 0; i < bb.ss.n; ++i) {
            hQFt += bb.ss.H.dot(bb.ss.Qc.col(i)) * bb.ss.F(j, i);
            hFQ += bb.ss.H.dot(bb.ss.F.col(i)) * bb.ss.Qc(i, j);
          }
          c.rows_of[bb.offset - kNav + j] = {hF, hQ, hQFt, hFQ};
        }
      }
    }
    for (int j = 0; j < n; ++j) {
      const std::array<double, 4>& r = c.rows_of[o + j];
      Fni.block<3, 1>(row, o + j) = col * b.ss.H(j);
      FniFii.block<3, 1>(row, o + j) = col * r[0];
      FniQii.block<3, 1>(row, o + j) = col * r[1];
      FniQiiFii.block<3, 1>(row, o + j) = col * r[2];
      FniFiiQii.block<3, 1>(row, o + j) = col * r[3];
    }
  }
  // extra states: random constants (Fii = 0, Qii = 0), only their Fni columns
  if (layout_.hasExtra()) addExtraCouplings(L, Fni, kNav);
  const double dt2 = dt * dt, dt3 = dt2 * dt;
  // the products below skip the zeros of F_ni, Q_nn (nine_row_product.hpp)
  Matrix9d Fnn2;
  nineRowProduct(Fnn2, Fnn, Fnn, true);
  T.A = Matrix9d::Identity() + Fnn * dt + Fnn2 * (0.5 * dt2);
  // B = Fni dt + (Fnn Fni + Fni Fii) dt^2/2
  T.B.resize(9, m);
  nineRowProduct(T.B, Fnn, Fni, true);
  T.B += FniFii;
  T.B *= 0.5 * dt2;
  T.B += Fni * dt;
  Matrix9d Qnn = Matrix9d::Zero();
  Qnn.block<3, 3>(kVel, kVel) = L.Qv;
  Qnn.block<3, 3>(kAtt, kAtt) = L.Qa;
  // Qd = Q dt + (FQ + QF') dt^2/2 + (F^2 Q + 2 F Q F' + Q F^2') dt^3/6 + O(dt^4),
  // with Q = blockdiag(Qnn, Qii) and F = [Fnn Fni; 0 Fii]:
  Matrix9d FQ, F2Q, FQFt;
  nineRowProduct(FQ, Fnn, Qnn, true);
  nineRowProduct(F2Q, Fnn2, Qnn, true);
  nineRowProduct(FQFt, FQ, Fnn.transpose(), true);
  nineRowProduct(FQFt, FniQii, Fni.transpose(), false);
  T.Q.topLeftCorner<9, 9>() = Qnn * dt + (FQ + FQ.transpose()) * (0.5 * dt2) +
                              (F2Q + F2Q.transpose() + 2.0 * FQFt) * (dt3 / 6.0);
  // Qni = Fni Qii dt^2/2 + (Fnn Fni Qii + Fni Fii Qii + 2 Fni Qii Fii') dt^3/6
  MatrixXd& Qni = c.Qni;
  Qni.resize(9, m);
  nineRowProduct(Qni, Fnn, FniQii, true);
  Qni += FniFiiQii + 2.0 * FniQiiFii;
  Qni *= dt3 / 6.0;
  Qni += FniQii * (0.5 * dt2);
  T.Q.topRightCorner(9, m) = Qni;
  T.Q.bottomLeftCorner(m, 9) = Qni.transpose();
}

namespace {
using SmallRow = Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, 8>;
using SmallCol = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 8, 1>;
// X <- X * D' for block-diagonal D (blocks given by the layout), columns in place.
void rightMulDt(Eigen::Ref<MatrixXd> X, const MatrixXd& D, const std::vector<ProcessBlock>& blocks) {
  for (const ProcessBlock& b : blocks) {
    const int o = b.offset - kNav, n = b.ss.n;
    if (n == 1) {
      X.col(o) *= D(o, o);
    } else if (n == 2) {  // DR, SIN: explicit 2x2 (a generic product per row is a BLAS call)
      const double d00 = D(o, o), d01 = D(o, o + 1), d10 = D(o + 1, o), d11 = D(o + 1, o + 1);
      for (Eigen::Index r = 0; r < X.rows(); ++r) {
        const double a = X(r, o), b = X(r, o + 1);
        X(r, o) = a * d00 + b * d01;
        X(r, o + 1) = a * d10 + b * d11;
      }
    } else if (n <= 8) {
      const auto Db = D.block(o, o, n, n);
      for (Eigen::Index r = 0; r < X.rows(); ++r) {
        const SmallRow y = X.row(r).segment(o, n) * Db.transpose();
        X.row(r).segment(o, n) = y;
      }
    } else {
      X.middleCols(o, n) = (X.middleCols(o, n) * D.block(o, o, n, n).transpose()).eval();
    }
  }
}
// X <- D * X (rows in place).
void leftMulD(Eigen::Ref<MatrixXd> X, const MatrixXd& D, const std::vector<ProcessBlock>& blocks) {
  for (const ProcessBlock& b : blocks) {
    const int o = b.offset - kNav, n = b.ss.n;
    if (n == 1) {
      X.row(o) *= D(o, o);
    } else if (n == 2) {
      const double d00 = D(o, o), d01 = D(o, o + 1), d10 = D(o + 1, o), d11 = D(o + 1, o + 1);
      for (Eigen::Index j = 0; j < X.cols(); ++j) {
        const double a = X(o, j), b = X(o + 1, j);
        X(o, j) = d00 * a + d01 * b;
        X(o + 1, j) = d10 * a + d11 * b;
      }
    } else if (n <= 8) {
      const auto Db = D.block(o, o, n, n);
      for (Eigen::Index j = 0; j < X.cols(); ++j) {
        const SmallCol y = Db * X.col(j).segment(o, n);
        X.col(j).segment(o, n) = y;
      }
    } else {
      X.middleRows(o, n) = (D.block(o, o, n, n) * X.middleRows(o, n)).eval();
    }
  }
}
}  // namespace

void ErrorStateEkf::accumulate(const Transition& T) {
  const auto& blocks = layout_.blocks();
  if (pending_ == 0 && cfg_.propagate_every == 1) {  // no accumulation: apply directly
    propagate(T.A, T.B, T.D, T.Q);
    return;
  }
  if (pending_ == 0) {
    A_acc_ = T.A;
    B_acc_ = T.B;
    D_acc_ = T.D;
    Q_acc_ = T.Q;
  } else {
    // Q_acc <- Phi_k Q_acc Phi_k' + Q_k, exact and cheap because the IMU block
    // of Q_acc stays block-diagonal (Groves 3.46 applied to the noise alone):
    const int m = layout_.imuSize();
    const Matrix9d Qnn = Q_acc_.topLeftCorner<9, 9>();
    const MatrixXd Qni = Q_acc_.topRightCorner(9, m);
    MatrixXd Qii = Q_acc_.bottomRightCorner(m, m);
    MatrixXd BQ(9, m);  // B_k Qii, block by block
    for (const ProcessBlock& b : blocks) {
      const int o = b.offset - kNav, n = b.ss.n;
      BQ.middleCols(o, n) = T.B.middleCols(o, n) * Qii.block(o, o, n, n);
    }
    MatrixXd M = T.A * Qni + BQ;
    Matrix9d Qnn1 = (T.A * Qnn + T.B * Qni.transpose()) * T.A.transpose();
    Qnn1.noalias() += M * T.B.transpose();
    rightMulDt(M, T.D, blocks);
    leftMulD(Qii, T.D, blocks);
    rightMulDt(Qii, T.D, blocks);
    Q_acc_.topLeftCorner<9, 9>() = Qnn1;
    Q_acc_.topRightCorner(9, m) = M;
    Q_acc_.bottomLeftCorner(m, 9) = M.transpose();
    Q_acc_.bottomRightCorner(m, m) = Qii;
    Q_acc_ += T.Q;
    // Phi_acc <- Phi_k Phi_acc (structure kept)
    MatrixXd BD = T.B;
    rightMulDt(BD, D_acc_.transpose(), blocks);  // B_k D_acc
    B_acc_ = T.A * B_acc_ + BD;
    A_acc_ = T.A * A_acc_;
    MatrixXd Dn = D_acc_;
    leftMulD(Dn, T.D, blocks);
    D_acc_ = Dn;
  }
  ++pending_;
  if (pending_ >= cfg_.propagate_every) applyTransition();
}

void ErrorStateEkf::applyTransition() {
  if (pending_ == 0) return;
  propagate(A_acc_, B_acc_, D_acc_, Q_acc_);
  pending_ = 0;
}

void ErrorStateEkf::propagate(const Matrix9d& A_acc_, const MatrixXd& B_acc_, const MatrixXd& D_acc_,
                              const MatrixXd& Q_acc_) {
  const int m = layout_.imuSize();
  const auto& blocks = layout_.blocks();
  // P <- Phi P Phi' + Q with Phi = [A B; 0 D] (Groves 3.46), block by block:
  //  P'nn = (A Pnn + B Pin) A' + (A Pni + B Pii) B'
  //  P'ni = (A Pni + B Pii) D'
  //  P'ii = D Pii D'
  const Matrix9d Pnn = P_.topLeftCorner<9, 9>();
  const auto Pni = P_.topRightCorner(9, m);
  auto Pii = P_.bottomRightCorner(m, m);
  // (products skipping the zeros of B and the IMU blocks: nine_row_product.hpp)
  MatrixXd& Mni = cache_->Mni;
  Mni.resize(9, m);
  Matrix9d Mnn, Pnn1;
  nineRowProduct(Mnn, A_acc_, Pnn, true);
  nineRowProduct(Mnn, B_acc_, Pni.transpose(), false);
  nineRowProduct(Mni, A_acc_, Pni, true);
  nineRowProduct(Mni, B_acc_, Pii, false);
  nineRowProduct(Pnn1, Mnn, A_acc_.transpose(), true);
  nineRowProduct(Pnn1, Mni, B_acc_.transpose(), false);
  rightMulDt(Mni, D_acc_, blocks);
  leftMulD(Pii, D_acc_, blocks);   // in place on P
  rightMulDt(Pii, D_acc_, blocks);
  P_.topLeftCorner<9, 9>() = Pnn1;
  P_.topRightCorner(9, m) = Mni;
  P_.bottomLeftCorner(m, 9) = Mni.transpose();
  P_ += Q_acc_;
  checkP("propagation");
}

void ErrorStateEkf::applyInterval() {
  if (iv_n_ == 0) return;
  // One transition over the whole interval T from the interval means of the
  // specific force (NED), of C_BtoN and of the rotated white-noise PSDs,
  // linearised at the end-of-interval state (Groves 2013 §14.2.4: the system
  // model may be propagated at a lower rate than the mechanization).
  const double T = iv_dt_, inv = 1.0 / T;
  Lin L;
  L.Fnn = navErrorDynamicsN(state(), iv_fN_ * inv);
  L.C = iv_C_ * inv;
  L.Qv = iv_Qv_ * inv;
  L.Qa = iv_Qa_ * inv;
  if (layout_.hasExtra()) {
    L.CDw = iv_CDw_ * inv;
    L.CSw = iv_CSw_ * inv;
    L.CDf = iv_CDf_ * inv;
    L.CSf = iv_CSf_ * inv;
    iv_CDw_.setZero();
    iv_CSw_.setZero();
    iv_CDf_.setZero();
    iv_CSf_.setZero();
  }
  Transition& Tr = cache_->tmp;
  buildTransition(L, T, Tr);
  propagate(Tr.A, Tr.B, Tr.D, Tr.Q);
  iv_n_ = 0;
  iv_dt_ = 0.0;
  iv_fN_.setZero();
  iv_C_.setZero();
  iv_Qv_.setZero();
  iv_Qa_.setZero();
}

void ErrorStateEkf::flushPropagation() {
  applyInterval();
  applyTransition();
}

void ErrorStateEkf::addSensorNoise(double dt, double psd_w, double psd_f) {
  if (!(dt > 0.0 && std::isfinite(dt) && psd_w >= 0.0 && std::isfinite(psd_w) && psd_f >= 0.0 &&
        std::isfinite(psd_f)))
    throw Error("sensor noise at t = " + formatNumber(state().t, 9) + " s: dt > 0 and finite PSDs >= 0 expected");
  flushPropagation();
  // Qd = G Qc G' dt with G = C_BtoN on psi and dv (Groves 14.80, first order)
  P_.diagonal().segment<3>(kVel).array() += psd_f * dt;
  P_.diagonal().segment<3>(kAtt).array() += psd_w * dt;
}

void ErrorStateEkf::checkP(const char* where) const {
  const auto d = P_.diagonal();
  const double scale = d.cwiseAbs().maxCoeff();
  for (int i = 0; i < d.size(); ++i) {
    if (!std::isfinite(d(i)) || d(i) < -1e-12 * (1.0 + scale))
      throw Error("filter covariance is not positive definite at t = " + formatNumber(state().t, 9) +
                  " s after " + where + " (state " + layout_.names()[i] + " variance " +
                  formatNumber(d(i), 9) + ")");
  }
}

void ErrorStateEkf::checkPositiveDefinite(const char* where) {
  // PdCheck (ekf.hpp): the correlation scale with each variance floored.
  const int N = size();
  Cache& c = *cache_;
  VectorXd& inv = c.inv;
  inv.resize(N);
  for (int i = 0; i < N; ++i) inv(i) = 1.0 / std::sqrt(std::max(P_(i, i), floor_(i)));
  MatrixXd& Pc = c.Pc;
  // the lower triangle only (P is symmetric after an update; the factorisation
  // reads the lower triangle), each entry (inv_i P_ij) inv_j as in
  // inv.asDiagonal() * P * inv.asDiagonal()
  Pc.resize(N, N);
  bool finite = true;
  for (int j = 0; j < N; ++j) {
    auto q = Pc.col(j).tail(N - j);
    q = (inv.tail(N - j).array() * P_.col(j).tail(N - j).array()) * inv(j);
    finite = finite && q.allFinite();
  }
  if (!finite)
    throw Error("filter covariance is not finite at t = " + formatNumber(state().t, 9) + " s after " + where);
  Pc.diagonal().array() += PdCheck::tolerance;
  // Factorised in place: the decomposition Eigen::LLT::compute() runs, without
  // its copy of Pc and its L1 norm (unused here); the same bits, the same verdict.
  if (Eigen::internal::llt_inplace<double, Eigen::Lower>::blocked(Pc) == -1) return;
  // not positive definite: Pc again as it was before the factorisation
  Pc = inv.asDiagonal() * P_ * inv.asDiagonal();
  Pc.diagonal().array() += PdCheck::tolerance;
  Pc.diagonal().array() -= PdCheck::tolerance;
  const Eigen::SelfAdjointEigenSolver<MatrixXd> es(Pc);
  const double lambda = es.eigenvalues()(0);
  if (es.info() != Eigen::Success || !(lambda >= -PdCheck::repair_limit)) {
    Eigen::Index k = 0;
    es.eigenvectors().col(0).cwiseAbs().maxCoeff(&k);
    throw Error("filter covariance is not positive definite at t = " + formatNumber(state().t, 9) + " s after " +
                where + " (eigenvalue " + formatNumber(lambda, 3) + " on the correlation scale, mostly state " +
                layout_.names()[k] + "; rounding is repaired down to -" + formatNumber(PdCheck::repair_limit, 3) + ")" +
                (cfg_.discretization == Discretization::Series
                     ? "; the series discretization is not positive definite over long IMU intervals: "
                       "filter.discretization vanloan is exact"
                     : ""));
  }
  // the eigenvalue floor: negative eigenvalues set to zero, P rebuilt
  const VectorXd l = es.eigenvalues().cwiseMax(0.0);
  Pc.noalias() = es.eigenvectors() * l.asDiagonal() * es.eigenvectors().transpose();
  const VectorXd d = inv.cwiseInverse();
  P_ = d.asDiagonal() * Pc * d.asDiagonal();
  P_ = (0.5 * (P_ + P_.transpose())).eval();
  if (pd_repairs_++ == 0) pd_first_t_ = state().t;
  pd_worst_ = std::min(pd_worst_, lambda);
}

ins::ImuSample ErrorStateEkf::corrected(const ins::ImuSample& raw) const {
  // Corrected output = raw - estimated error (closed loop, Groves 14.? feedback).
  const Eigen::Matrix<double, 6, 1> e = sensorErrors();
  ins::ImuSample s = raw;
  s.dtheta_B -= e.head<3>() * raw.dt;
  s.dv_B -= e.tail<3>() * raw.dt;
  if (layout_.hasExtra()) {
    // corrected = M_est^-1 (raw - b_est), M_est = I + diag(s_est) + [m_est x] (state_layout.hpp)
    if (layout_.extraIndex(Extra::GyroScale) >= 0 || layout_.extraIndex(Extra::GyroMisalignment) >= 0) {
      const Eigen::Matrix3d M = Eigen::Matrix3d::Identity() + Eigen::Matrix3d(extra3(Extra::GyroScale).asDiagonal()) +
                                skew(extra3(Extra::GyroMisalignment));
      s.dtheta_B = M.inverse() * s.dtheta_B;
    }
    if (layout_.extraIndex(Extra::AccScale) >= 0 || layout_.extraIndex(Extra::AccMisalignment) >= 0) {
      const Eigen::Matrix3d M = Eigen::Matrix3d::Identity() + Eigen::Matrix3d(extra3(Extra::AccScale).asDiagonal()) +
                                skew(extra3(Extra::AccMisalignment));
      s.dv_B = M.inverse() * s.dv_B;
    }
  }
  return s;
}

void ErrorStateEkf::primeRates(const ins::ImuSample& first) {
  if (!(first.dt > 0.0) || !std::isfinite(first.dt))
    throw Error("IMU sample at t = " + formatNumber(first.t, 9) + " s has non-positive interval dt");
  const ins::ImuSample s = corrected(first);
  w_IB_B_ = s.w_IB_B();
  f_B_ = s.f_B();
  ring_count_ = 0;
  pushRate(w_IB_B_, first.dt);
}

void ErrorStateEkf::pushRate(const Vector3d& w, double dt) {
  const int K = std::clamp(static_cast<int>(std::lround(kRateSpanS / dt)), 1, kRateRing - 1);
  if (ring_count_ >= K) {
    const Vector3d& old = rate_ring_[static_cast<std::size_t>((ring_next_ - K + kRateRing) % kRateRing)];
    dw_IB_B_ = (w - old) / (K * dt);
  } else {
    dw_IB_B_.setZero();
  }
  rate_ring_[static_cast<std::size_t>(ring_next_)] = w;
  ring_next_ = (ring_next_ + 1) % kRateRing;
  ring_count_ = std::min(ring_count_ + 1, kRateRing);
  w_end_IB_B_ = w + (0.5 * dt) * dw_IB_B_;
}

void ErrorStateEkf::carryInitialStateToImuClock() {
  const int k = layout_.extraIndex(Extra::TimeOffset);
  if (k < 0) return;
  flushPropagation();
  const Vector9d J = stateRate();
  const double d0 = extra(Extra::TimeOffset);
  if (d0 != 0.0) mech_.setState(applyNavError(state(), -d0 * J));  // the truth at t0 - d0
  MatrixXd T = MatrixXd::Identity(size(), size());
  T.block(0, k, 9, 1) = -J;  // dx_nav = J (d - d0) = -J dd
  P_ = (T * P_ * T.transpose()).eval();
  P_ = (0.5 * (P_ + P_.transpose())).eval();
  cache_->nominal_valid = false;
}

void ErrorStateEkf::predict(const ins::ImuSample& raw) {
  if (!(raw.dt > 0.0) || !std::isfinite(raw.dt))
    throw Error("IMU sample at t = " + formatNumber(raw.t, 9) + " s has non-positive interval dt");
  if (pending_ > 0) applyTransition();  // left over from predictCovariance()
  const ins::ImuSample s = corrected(raw);
  w_IB_B_ = s.w_IB_B();
  pushRate(w_IB_B_, raw.dt);
  f_B_ = s.f_B();
  mech_.step(s);
  cache_->nominal_valid = false;
  const auto& blocks = layout_.blocks();
  if (cfg_.propagate_every == 1) {
    Transition& T = cache_->tmp;
    buildTransition(currentLin(), raw.dt, T);
    // deterministic propagation of the IMU-error estimates with the exact blocks
    for (const ProcessBlock& b : blocks) {
      const int o = b.offset - kNav, n = b.ss.n;
      if (n == 1) {
        x_imu_(o) *= T.D(o, o);
      } else if (n > 8) {
        x_imu_.segment(o, n) = (T.D.block(o, o, n, n) * x_imu_.segment(o, n)).eval();
      } else {
        const SmallCol y = T.D.block(o, o, n, n) * x_imu_.segment(o, n);
        x_imu_.segment(o, n) = y;
      }
    }
    accumulate(T);
    return;
  }
  // Lower-rate covariance propagation: IMU-error estimates every sample with
  // the exact blocks, covariance once per interval (applyInterval).
  const Cache::Blocks& cb = cache_->blocksFor(blocks, raw.dt);
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const int o = blocks[k].offset - kNav, n = blocks[k].ss.n;
    if (n == 1) {
      x_imu_(o) *= cb.Phi[k](0, 0);
    } else if (n == 2) {
      const MatrixXd& F = cb.Phi[k];
      const double a = x_imu_(o), b = x_imu_(o + 1);
      x_imu_(o) = F(0, 0) * a + F(0, 1) * b;
      x_imu_(o + 1) = F(1, 0) * a + F(1, 1) * b;
    } else if (n > 8) {
      x_imu_.segment(o, n) = (cb.Phi[k] * x_imu_.segment(o, n)).eval();
    } else {
      const SmallCol y = cb.Phi[k] * x_imu_.segment(o, n);
      x_imu_.segment(o, n) = y;
    }
  }
  const Eigen::Matrix3d C = state().C_BtoN();
  const auto& psd = layout_.whitePsd();
  iv_dt_ += raw.dt;
  iv_fN_ += C * (f_B_ * raw.dt);
  iv_C_ += C * raw.dt;
  // C diag(psd) C' dt; = psd I dt when the three axes share the PSD (C orthonormal)
  auto addPsd = [&](Eigen::Matrix3d& acc, double p0, double p1, double p2) {
    if (p0 == p1 && p1 == p2) {
      acc.diagonal().array() += p0 * raw.dt;
    } else {
      const Eigen::Matrix3d Cs = C * Vector3d(p0 * raw.dt, p1 * raw.dt, p2 * raw.dt).asDiagonal();
      acc.noalias() += Cs * C.transpose();
    }
  };
  addPsd(iv_Qv_, psd[3], psd[4], psd[5]);
  addPsd(iv_Qa_, psd[0], psd[1], psd[2]);
  if (layout_.hasExtra()) {
    iv_CDw_.noalias() += C * (w_IB_B_ * raw.dt).asDiagonal();
    iv_CSw_.noalias() += C * skew(w_IB_B_ * raw.dt);
    iv_CDf_.noalias() += C * (f_B_ * raw.dt).asDiagonal();
    iv_CSf_.noalias() += C * skew(f_B_ * raw.dt);
  }
  if (++iv_n_ >= cfg_.propagate_every) applyInterval();
}

void ErrorStateEkf::predictCovariance(const ins::NavState& nominal, const Vector3d& w_IB_B,
                                      const Vector3d& f_B, double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw Error("covariance propagation at t = " + formatNumber(nominal.t, 9) + " s: dt must be > 0");
  applyInterval();  // left over from predict()
  Cache& c = *cache_;
  const bool same = c.nominal_valid && c.nominal_dt == dt && c.w == w_IB_B && c.f == f_B &&
                    sameState(c.nominal, nominal);
  mech_.setState(nominal);
  w_IB_B_ = w_IB_B;
  f_B_ = f_B;
  w_end_IB_B_ = w_IB_B;  // the nominal rate at the interval's end
  dw_IB_B_.setZero();
  if (!same) {
    buildTransition(currentLin(), dt, c.T);
    c.nominal = nominal;
    c.w = w_IB_B;
    c.f = f_B;
    c.nominal_dt = dt;
    c.nominal_valid = true;
  }
  accumulate(c.T);
}

MatrixXd ErrorStateEkf::H_gnssPosition(const Vector3d& lever_B, double dt_meas) const {
  const Vector3d l = lever_B - extra3(Extra::LeverArm);
  const double tau = dt_meas + extra(Extra::TimeOffset);
  MatrixXd H = MatrixXd::Zero(3, size());
  H.block<3, 3>(0, kPos).setIdentity();
  // p_ant = p + C l: d(C l) = psi x (C l) = -[(C l) x] psi (Groves 14.110 with our signs)
  H.block<3, 3>(0, kAtt) = -skew(state().C_BtoN() * l);
  // lever-arm error e = told - true: l_used - l_true = -de
  if (const int k = layout_.extraIndex(Extra::LeverArm); k >= 0) H.block<3, 3>(0, k) = -state().C_BtoN();
  // carried to the measurement epoch: p_ant + v_ant tau
  if (tau != 0.0) H += tau * H_antennaVelocity(l);
  // time offset: d(p_ant + v_ant tau)/d(d_est) = v_ant
  if (const int k = layout_.extraIndex(Extra::TimeOffset); k >= 0) H.col(k) = antennaVelocity(l);
  return H;
}

Vector3d ErrorStateEkf::antennaVelocity(const Vector3d& l) const {
  const ins::NavState& x = state();
  const Eigen::Matrix3d C = x.C_BtoN();
  const Vector3d w_ie = earth::w_IE_N(x.lat);
  return x.v_N + C * w_end_IB_B_.cross(l) - w_ie.cross(C * l);
}

Vector3d ErrorStateEkf::accelerationN() const {
  // dv/dt = C f_B + g_N - (2 w_IE_N + w_EN_N) x v_N (Groves 5.54)
  const ins::NavState& x = state();
  const Vector3d w_ie = earth::w_IE_N(x.lat);
  return x.C_BtoN() * f_B_ + earth::gravity_N(x.lat, x.h) -
         (2.0 * w_ie + earth::w_EN_N(x.lat, x.h, x.v_N)).cross(x.v_N);
}

Vector3d ErrorStateEkf::w_EB_B(const Eigen::Matrix3d& C_BtoN) const {
  return w_end_IB_B_ - C_BtoN.transpose() * earth::w_IE_N(state().lat);
}

Vector3d ErrorStateEkf::antennaAcceleration(const Vector3d& l) const {
  // d/dt [v_N + C (w x l)] = a_N + C (w x (w x l)) + C (dw/dt x l), w the body
  // rate w.r.t. the Earth (Earth rate and transport rate in C's derivative left out)
  const Eigen::Matrix3d C = state().C_BtoN();
  const Vector3d w = w_EB_B(C);
  return accelerationN() + C * (w.cross(w.cross(l)) + dw_IB_B_.cross(l));
}

MatrixXd ErrorStateEkf::H_antennaVelocity(const Vector3d& lever_B) const {
  MatrixXd H = MatrixXd::Zero(3, size());
  const Eigen::Matrix3d C = state().C_BtoN();
  const Vector3d w_ie = earth::w_IE_N(state().lat);
  H.block<3, 3>(0, kVel).setIdentity();
  // v_ant = v + C (w_IB_B x l) - w_IE_N x (C l)  (Groves 14.111)
  H.block<3, 3>(0, kAtt) = -skew(C * w_end_IB_B_.cross(lever_B)) + skew(w_ie) * skew(C * lever_B);
  // gyro error: d(w) = -h_c dx_imu -> C (dw x l) = C [l x] Hg dx
  if (layout_.imuSize() > 0 && lever_B.squaredNorm() > 0.0) {
    H.rightCols(layout_.imuSize()) = C * skew(lever_B) * layout_.gyroRows();
  }
  if (layout_.hasExtra()) {
    // dw = -diag(w) ds_g + [w x] dm_g enters as C (dw x l) = -C [l x] dw
    if (const int k = layout_.extraIndex(Extra::GyroScale); k >= 0)
      H.block<3, 3>(0, k) = C * skew(lever_B) * w_end_IB_B_.asDiagonal();
    if (const int k = layout_.extraIndex(Extra::GyroMisalignment); k >= 0)
      H.block<3, 3>(0, k) = -C * skew(lever_B) * skew(w_end_IB_B_);
    // lever-arm error: l_used - l_true = -de, d v_ant / d l = C [w x] - [w_IE x] C
    if (const int k = layout_.extraIndex(Extra::LeverArm); k >= 0)
      H.block<3, 3>(0, k) = -(C * skew(w_end_IB_B_) - skew(w_ie) * C);
  }
  return H;
}

MatrixXd ErrorStateEkf::H_antennaRotationAcceleration(const Vector3d& l) const {
  // C u, u = w x (w x l) + dw/dt x l (antennaAcceleration): with C_est = (I + [psi x]) C,
  // d(C u) = -[(C u) x] psi + C du; du = M dw + ([w x][w x] + [dw/dt x]) dl with
  // M = -[(w x l) x] - [w x][l x]; dw = -Hg dx_imu (- diag(w) ds_g + [w x] dm_g); dl = -de
  MatrixXd H = MatrixXd::Zero(3, size());
  const Eigen::Matrix3d C = state().C_BtoN();
  const Vector3d w = w_EB_B(C);
  const Vector3d u = w.cross(w.cross(l)) + dw_IB_B_.cross(l);
  H.block<3, 3>(0, kAtt) = -skew(C * u);
  const Eigen::Matrix3d CM = C * (-skew(w.cross(l)) - skew(w) * skew(l));
  if (layout_.imuSize() > 0) {
    H.rightCols(layout_.imuSize()) = -CM * layout_.gyroRows();
  }
  if (layout_.hasExtra()) {
    if (const int k = layout_.extraIndex(Extra::GyroScale); k >= 0)
      H.block<3, 3>(0, k) = -CM * w_end_IB_B_.asDiagonal();
    if (const int k = layout_.extraIndex(Extra::GyroMisalignment); k >= 0)
      H.block<3, 3>(0, k) = CM * skew(w_end_IB_B_);
    if (const int k = layout_.extraIndex(Extra::LeverArm); k >= 0)
      H.block<3, 3>(0, k) = -C * (skew(w) * skew(w) + skew(dw_IB_B_));
  }
  return H;
}

MatrixXd ErrorStateEkf::H_gnssVelocity(const Vector3d& lever_B, double dt_meas) const {
  const Vector3d l = lever_B - extra3(Extra::LeverArm);
  const double tau = dt_meas + extra(Extra::TimeOffset);
  MatrixXd H = H_antennaVelocity(l);
  // carried to the measurement epoch with the antenna's acceleration: dv/dt,
  // whose linearisation is the velocity rows of F (Groves 14.65-14.69 and the
  // accelerometer coupling), and the lever arm's rotation terms
  if (tau != 0.0) {
    H += tau * F().middleRows(kVel, 3);
    if (l.squaredNorm() > 0.0) H += tau * H_antennaRotationAcceleration(l);
  }
  // time offset: d(v_ant + a_N tau)/d(d_est) = a_N
  if (const int k = layout_.extraIndex(Extra::TimeOffset); k >= 0) H.col(k) = antennaAcceleration(l);
  return H;
}

MatrixXd ErrorStateEkf::H_zeroVelocity() const {
  MatrixXd H = MatrixXd::Zero(3, size());
  H.block<3, 3>(0, kVel).setIdentity();
  return H;
}

MatrixXd ErrorStateEkf::H_nonHolonomic(const Vector3d& point_B) const {
  // v_P_B = C' v_N + (w_IB_B - C' w_IE_N) x l with C = C_BtoN. With
  // C_est = (I + [psi x]) C: C_est' = C' (I - [psi x]), so
  //   d(C' v) = C' dv + C' [v x] psi,   d(-(C' w_ie) x l) = [l x] C' [w_ie x] psi,
  // and the corrected gyro error dw = -Hg dx_imu enters as dw x l = [l x] Hg dx_imu.
  MatrixXd H3 = MatrixXd::Zero(3, size());
  const Eigen::Matrix3d Ct = state().C_BtoN().transpose();
  const Vector3d w_ie = earth::w_IE_N(state().lat);
  H3.block<3, 3>(0, kVel) = Ct;
  H3.block<3, 3>(0, kAtt) = Ct * skew(state().v_N) + skew(point_B) * Ct * skew(w_ie);
  if (layout_.imuSize() > 0 && point_B.squaredNorm() > 0.0) {
    H3.rightCols(layout_.imuSize()) = skew(point_B) * layout_.gyroRows();
    // extra gyro states: dw = -diag(w) ds_g + [w x] dm_g enters as dw x l = -[l x] dw
    if (const int k = layout_.extraIndex(Extra::GyroScale); k >= 0)
      H3.block<3, 3>(0, k) = skew(point_B) * w_IB_B_.asDiagonal();
    if (const int k = layout_.extraIndex(Extra::GyroMisalignment); k >= 0)
      H3.block<3, 3>(0, k) = -skew(point_B) * skew(w_IB_B_);
  }
  return H3.bottomRows(2);
}

MatrixXd ErrorStateEkf::H_baro(double dt_meas) const {
  MatrixXd H = MatrixXd::Zero(1, size());
  H(0, kPos + 2) = -1.0;  // h_est - h = -dp_D
  // carried to the measurement epoch: h - v_D tau; the offset's column -v_D
  const double tau = dt_meas + extra(Extra::TimeOffset);
  if (tau != 0.0) H(0, kVel + 2) = -tau;
  if (const int k = layout_.extraIndex(Extra::TimeOffset); k >= 0) H(0, k) = -state().v_N.z();
  return H;
}

UpdateResult ErrorStateEkf::update(const VectorXd& dz, const MatrixXd& H, const MatrixXd& R,
                                   bool feedback) {
  flushPropagation();
  const int mz = static_cast<int>(dz.size());
  Cache& c = *cache_;
  UpdateResult res;
  res.t = state().t;
  MatrixXd& PHt = c.PHt;
  PHt.noalias() = P_ * H.transpose();
  res.S = R;
  res.S.noalias() += H * PHt;
  res.innovation = dz;
  Eigen::LLT<MatrixXd> llt;
  auto factor = [&](const MatrixXd& S) {
    llt.compute(S);
    if (llt.info() != Eigen::Success || !S.allFinite())
      throw Error("innovation covariance not positive definite at t = " + formatNumber(res.t, 9) + " s");
  };
  factor(res.S);
  res.nis = dz.dot(llt.solve(dz));
  if (cfg_.gate_probability > 0.0) {
    const boost::math::chi_squared chi2(mz);
    res.gate = boost::math::quantile(chi2, cfg_.gate_probability);
    if (res.nis > res.gate) {
      if (cfg_.gate_readmit_after == 0 || consecutive_rejections_ < cfg_.gate_readmit_after) {
        res.accepted = false;
        ++rejections_;
        ++consecutive_rejections_;
        last_ = res;
        return res;
      }
      // Re-admission (fading memory, Simon 2006 §7.4): P <- lambda P with
      // lambda = NIS / gate, then the ordinary update with the inflated P.
      res.readmitted = true;
      res.inflation = res.nis / res.gate;
      P_ *= res.inflation;
      PHt *= res.inflation;
      MatrixXd S2 = R;
      S2.noalias() += H * PHt;
      factor(S2);
    }
  }
  consecutive_rejections_ = 0;
  MatrixXd& K = c.K;
  K = llt.solve(PHt.transpose()).transpose();  // K = P H' S^-1 (Groves 3.21)
  // Joseph form (I-KH) P (I-KH)' + K R K' (Groves 3.58), expanded:
  // P - K (PH')' - (PH') K' + K S K', with K S K' = (K L)(K L)' for S = L L';
  // as symmetric rank updates of the lower triangle, then mirrored.
  MatrixXd& KL = c.KS;
  KL.noalias() = K * llt.matrixL();
  auto Pl = P_.selfadjointView<Eigen::Lower>();
  for (int j = 0; j < mz; ++j) Pl.rankUpdate(K.col(j), PHt.col(j), -1.0);
  // A scalar measurement (baro) adds the rank-one (K L)(K L)': as a vector,
  // P_ij + k_i k_j, the same sum the general product forms with one term,
  // without its packing.
  if (mz == 1)
    Pl.rankUpdate(KL.col(0), 1.0);
  else
    Pl.rankUpdate(KL, 1.0);
  P_.triangularView<Eigen::StrictlyUpper>() = P_.transpose();
  if (feedback) {
    const VectorXd dx = K * dz;  // estimated error (estimate minus truth)
    mech_.setState(correctNav(state(), dx.head<9>()));
    x_imu_ -= dx.tail(layout_.imuSize());
    c.nominal_valid = false;
  }
  checkP("update");
  checkPositiveDefinite("update");
  last_ = res;
  return res;
}

VectorXd ErrorStateEkf::residualGnssPosition(const earth::Geodetic& z, const Vector3d& lever_B,
                                             double dt_meas) const {
  const Vector3d l = lever_B - extra3(Extra::LeverArm);
  const double tau = dt_meas + extra(Extra::TimeOffset);
  const ins::NavState& x = state();
  const earth::Radii r = earth::radii(x.lat);
  const Vector3d l_N = x.C_BtoN() * l;
  const earth::Geodetic ant{x.lat + l_N.x() / (r.R_N + x.h),
                            x.lon + l_N.y() / ((r.R_E + x.h) * std::cos(x.lat)), x.h - l_N.z()};
  VectorXd dz = earth::curvilinearDiffNed(ant, z);
  if (tau != 0.0) dz += tau * antennaVelocity(l);
  return dz;
}

UpdateResult ErrorStateEkf::updateGnssPosition(const earth::Geodetic& z, const Vector3d& sigma,
                                               const Vector3d& lever_B, double dt_meas) {
  requirePositiveSigma(sigma, "GNSS position sigma", state().t);
  flushPropagation();
  return update(residualGnssPosition(z, lever_B, dt_meas), H_gnssPosition(lever_B, dt_meas),
                MatrixXd(sigma.cwiseAbs2().asDiagonal()));
}

VectorXd ErrorStateEkf::residualGnssVelocity(const Vector3d& z_N, const Vector3d& lever_B,
                                             double dt_meas) const {
  const Vector3d l = lever_B - extra3(Extra::LeverArm);
  const double tau = dt_meas + extra(Extra::TimeOffset);
  Vector3d v_ant = antennaVelocity(l);
  if (tau != 0.0) v_ant += antennaAcceleration(l) * tau;
  return v_ant - z_N;
}

UpdateResult ErrorStateEkf::updateGnssVelocity(const Vector3d& z_N, const Vector3d& sigma,
                                               const Vector3d& lever_B, double dt_meas) {
  requirePositiveSigma(sigma, "GNSS velocity sigma", state().t);
  flushPropagation();
  return update(residualGnssVelocity(z_N, lever_B, dt_meas), H_gnssVelocity(lever_B, dt_meas),
                MatrixXd(sigma.cwiseAbs2().asDiagonal()));
}

UpdateResult ErrorStateEkf::updateZeroVelocity(double sigma) {
  requirePositiveSigma(sigma, "zero-velocity update sigma", state().t);
  flushPropagation();
  const VectorXd dz = state().v_N;
  return update(dz, H_zeroVelocity(), MatrixXd::Identity(3, 3) * (sigma * sigma));
}

Eigen::Vector2d ErrorStateEkf::residualNonHolonomic(const Vector3d& point_B) const {
  const Eigen::Matrix3d Ct = state().C_BtoN().transpose();
  const Vector3d w_EB_B = w_IB_B_ - Ct * earth::w_IE_N(state().lat);
  const Vector3d v_P = Ct * state().v_N + w_EB_B.cross(point_B);
  return v_P.tail<2>();
}

UpdateResult ErrorStateEkf::updateNonHolonomic(double sigma_lat, double sigma_vert,
                                               const Vector3d& point_B) {
  requirePositiveSigma(Eigen::Vector2d(sigma_lat, sigma_vert), "non-holonomic constraint sigmas", state().t);
  flushPropagation();
  const VectorXd dz = residualNonHolonomic(point_B);
  MatrixXd R = MatrixXd::Zero(2, 2);
  R(0, 0) = sigma_lat * sigma_lat;
  R(1, 1) = sigma_vert * sigma_vert;
  return update(dz, H_nonHolonomic(point_B), R);
}

UpdateResult ErrorStateEkf::updateBaro(double h_meas, double sigma, double dt_meas) {
  requirePositiveSigma(sigma, "barometer sigma", state().t);
  const double tau = dt_meas + extra(Extra::TimeOffset);
  VectorXd dz(1);
  dz(0) = state().h - h_meas;
  if (tau != 0.0) dz(0) -= state().v_N.z() * tau;
  return update(dz, H_baro(dt_meas), MatrixXd::Constant(1, 1, sigma * sigma));
}

void ErrorStateEkf::discretize(double dt, MatrixXd& Phi, MatrixXd& Qd) const {
  Transition T;
  buildTransition(currentLin(), dt, T);
  const int m = layout_.imuSize(), N = size();
  Phi = MatrixXd::Zero(N, N);
  Phi.topLeftCorner<9, 9>() = T.A;
  Phi.topRightCorner(9, m) = T.B;
  Phi.bottomRightCorner(m, m) = T.D;
  Qd = T.Q;
}

}  // namespace navimpact::filter
