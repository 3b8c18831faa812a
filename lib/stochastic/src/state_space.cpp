// State-space blocks of the latent processes with exact discretisation (each
// kind's F, Qc, H, P0 in processes/<name>.cpp).
// Closed forms for the blocks navimpact builds (GM, RW, DR, SIN); any other
// (F, Qc) pair falls back to Van Loan's method (Van Loan 1978, "Computing
// integrals involving the matrix exponential"; Groves 2013 §3.2.4).
#include "navimpact/stochastic/state_space.hpp"

#include <cmath>
#include <unsupported/Eigen/MatrixFunctions>

#include "kind.hpp"
#include "navimpact/core/error.hpp"

namespace navimpact::stochastic {

namespace {

/// Van Loan: exp([[-F, Qc], [0, F^T]] dt) = [[., G12], [0, G22]];
/// Phi = G22^T, Qd = Phi G12.
void vanLoan(const Eigen::MatrixXd& F, const Eigen::MatrixXd& Qc, double dt, Eigen::MatrixXd* Phi,
             Eigen::MatrixXd* Qd) {
  const Eigen::Index n = F.rows();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  M.topLeftCorner(n, n) = -F * dt;
  M.topRightCorner(n, n) = Qc * dt;
  M.bottomRightCorner(n, n) = F.transpose() * dt;
  const Eigen::MatrixXd E = M.exp();
  const Eigen::MatrixXd P = E.bottomRightCorner(n, n).transpose();
  if (Phi) *Phi = P;
  if (Qd) {
    *Qd = P * E.topRightCorner(n, n);
    *Qd = 0.5 * (*Qd + Qd->transpose());
  }
}

bool isNilpotent2(const Eigen::MatrixXd& F) {
  return F.rows() == 2 && F(0, 0) == 0.0 && F(1, 0) == 0.0 && F(1, 1) == 0.0;
}

bool isRotation2(const Eigen::MatrixXd& F) {
  return F.rows() == 2 && F(0, 0) == 0.0 && F(1, 1) == 0.0 && F(0, 1) == -F(1, 0);
}

}  // namespace

Eigen::MatrixXd StateSpaceBlock::Phi(double dt) const {
  if (n == 0) return Eigen::MatrixXd(0, 0);
  if (n == 1) return Eigen::MatrixXd::Constant(1, 1, std::exp(F(0, 0) * dt));
  if (isNilpotent2(F)) {
    // F^2 = 0: exp(F dt) = I + F dt (bias' = rate).
    return Eigen::MatrixXd::Identity(2, 2) + F * dt;
  }
  if (isRotation2(F)) {
    // Harmonic oscillator: exp(F dt) is a rotation by w dt.
    const double w = F(0, 1), c = std::cos(w * dt), s = std::sin(w * dt);
    Eigen::MatrixXd P(2, 2);
    P << c, s, -s, c;
    return P;
  }
  Eigen::MatrixXd P;
  vanLoan(F, Qc, dt, &P, nullptr);
  return P;
}

Eigen::MatrixXd StateSpaceBlock::Qd(double dt) const {
  if (n == 0) return Eigen::MatrixXd(0, 0);
  if (Qc.isZero(0.0)) return Eigen::MatrixXd::Zero(n, n);
  if (n == 1) {
    const double f = F(0, 0);
    // int_0^dt e^{2 f s} Qc ds = Qc (e^{2 f dt} - 1) / (2 f), stable via expm1;
    // f = 0 (random walk): Qc dt.
    const double q = (f == 0.0) ? Qc(0, 0) * dt : Qc(0, 0) * std::expm1(2.0 * f * dt) / (2.0 * f);
    return Eigen::MatrixXd::Constant(1, 1, q);
  }
  Eigen::MatrixXd Q;
  vanLoan(F, Qc, dt, nullptr, &Q);
  return Q;
}

StateSpaceBlock stateSpace(const Process& p, double rate_hz) {
  if (!(rate_hz > 0.0)) throw Error("stateSpace: rate_hz must be > 0");
  const detail::KindDef& def = detail::kindDef(p.kind);
  StateSpaceBlock b;
  const int n = def.stateCount();
  b.n = n;
  b.F = Eigen::MatrixXd::Zero(n, n);
  b.Qc = Eigen::MatrixXd::Zero(n, n);
  b.H = Eigen::RowVectorXd::Zero(n);
  b.P0 = Eigen::MatrixXd::Zero(n, n);
  def.stateSpace(p, rate_hz, b);  // processes/<name>.cpp
  if (static_cast<int>(b.names.size()) != n)
    throw Error(std::string("internal: state-space block of ") + def.info().name + " has " +
                std::to_string(n) + " states and " + std::to_string(b.names.size()) + " labels");
  return b;
}

}  // namespace navimpact::stochastic
