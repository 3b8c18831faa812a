// Linearised local-navigation-frame INS error model (Groves 2013 §14.2.4),
// position error in metres NED. Derivation notes in error_model.hpp.
#include "navimpact/filter/error_model.hpp"

#include <limits>

#include <cmath>

#include "navimpact/core/earth.hpp"

namespace navimpact::filter {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using ins::skew;

Matrix9d navErrorDynamics(const ins::NavState& x, const Vector3d& f_B) {
  return navErrorDynamicsN(x, x.C_BtoN() * f_B);
}

Matrix9d navErrorDynamicsN(const ins::NavState& x, const Vector3d& f_N) {
  // sin, cos, tan and the radii once (the values earth::radii, w_IE_N and w_EN_N
  // of x.lat compute, bit for bit)
  const earth::LatitudeTerms lt(x.lat);
  const earth::Radii& r = lt.r;
  const double rN = r.R_N + x.h, rE = r.R_E + x.h;
  const double sL = lt.sin_lat, cL = lt.cos_lat, tL = sL / cL;
  const double vN = x.v_N.x(), vE = x.v_N.y(), vD = x.v_N.z();
  const double W = earth::kOmegaIE;
  const Vector3d w_ie = earth::w_IE_N(lt);
  const Vector3d w_en = earth::w_EN_N(lt, x.h, x.v_N);

  // d(omega)/d(dp): column 0 = d/dlat / rN, column 2 = -d/dh (dp_D = -dh).
  Matrix3d Wie_r = Matrix3d::Zero();
  Wie_r.col(0) = Vector3d(-W * sL, 0.0, -W * cL) / rN;  // Groves 14.67 (curvilinear form)
  Matrix3d Wen_r = Matrix3d::Zero();
  const Vector3d dwen_dlat(-vE * r.dR_E_dlat / (rE * rE), vN * r.dR_N_dlat / (rN * rN),
                           -vE / (rE * cL * cL) + vE * tL * r.dR_E_dlat / (rE * rE));
  const Vector3d dwen_dh(-vE / (rE * rE), vN / (rN * rN), vE * tL / (rE * rE));
  Wen_r.col(0) = dwen_dlat / rN;
  Wen_r.col(2) = -dwen_dh;
  Matrix3d Wen_v = Matrix3d::Zero();  // Groves 14.68
  Wen_v(0, 1) = 1.0 / rE;
  Wen_v(1, 0) = -1.0 / rN;
  Wen_v(2, 1) = -tL / rE;

  // Gravity error (Groves 14.69 with the ellipsoidal gradient).
  double dgD_dlat = 0, dgD_dh = 0;
  earth::gravityGradient(lt, x.h, dgD_dlat, dgD_dh);
  const double dgN_dh = earth::gravity_N(x.lat, x.h + 1.0).x() - earth::gravity_N(x.lat, x.h).x();
  Matrix3d G_r = Matrix3d::Zero();
  G_r(2, 0) = dgD_dlat / rN;
  G_r(2, 2) = -dgD_dh;
  G_r(0, 2) = -dgN_dh;

  Matrix9d F = Matrix9d::Zero();
  // position rows (metre form of Groves 14.70-14.71)
  F(0, 0) = -vD / rN;
  F(0, 2) = vN / rN;
  F(1, 0) = vE * (tL - r.dR_E_dlat / rE) / rN;
  F(1, 1) = r.dR_E_dlat * vN / (rN * rE) - vD / rE - tL * vN / rN;
  F(1, 2) = vE / rE;
  F.block<3, 3>(0, 3).setIdentity();
  // velocity rows (Groves 14.65-14.69)
  const Matrix3d Vx = skew(x.v_N);
  F.block<3, 3>(3, 0) = G_r + Vx * (2.0 * Wie_r + Wen_r);
  F.block<3, 3>(3, 3) = Vx * Wen_v - skew(2.0 * w_ie + w_en);
  F.block<3, 3>(3, 6) = -skew(f_N);
  // attitude rows (Groves 14.64)
  F.block<3, 3>(6, 0) = -(Wie_r + Wen_r);
  F.block<3, 3>(6, 3) = -Wen_v;
  F.block<3, 3>(6, 6) = -skew(w_ie + w_en);
  return F;
}

Vector9d navError(const ins::NavState& est, const ins::NavState& truth) {
  Vector9d dx;
  dx.segment<3>(0) = earth::curvilinearDiffNed(est.geodetic(), truth.geodetic());
  dx.segment<3>(3) = est.v_N - truth.v_N;
  // C_est C_true' = I + [psi x]  (small angle), exact via the rotation vector.
  const Eigen::AngleAxisd aa(est.q_BtoN * truth.q_BtoN.conjugate());
  dx.segment<3>(6) = aa.angle() * aa.axis();
  // an unknown attitude (a reference with positions only: NaN) stays unknown;
  // a NaN from two known attitudes is the zero rotation
  if (!truth.q_BtoN.coeffs().allFinite() || !est.q_BtoN.coeffs().allFinite())
    dx.segment<3>(6).setConstant(std::numeric_limits<double>::quiet_NaN());
  else if (dx.segment<3>(6).hasNaN())
    dx.segment<3>(6).setZero();
  return dx;
}

ins::NavState applyNavError(const ins::NavState& truth, const Vector9d& dx) {
  const earth::Radii r = earth::radii(truth.lat);
  ins::NavState e = truth;
  e.lat = truth.lat + dx(0) / (r.R_N + truth.h);
  e.lon = truth.lon + dx(1) / ((r.R_E + truth.h) * std::cos(truth.lat));
  e.h = truth.h - dx(2);
  e.v_N = truth.v_N + dx.segment<3>(3);
  e.q_BtoN = (ins::quatFromRotVec(dx.segment<3>(6)) * truth.q_BtoN).normalized();
  return e;
}

ins::NavState correctNav(const ins::NavState& est, const Vector9d& dx) {
  // Groves 14.7-14.9 (closed loop), signs for estimate-minus-truth errors.
  const earth::Radii r = earth::radii(est.lat);
  ins::NavState x = est;
  x.lat = est.lat - dx(0) / (r.R_N + est.h);
  x.lon = est.lon - dx(1) / ((r.R_E + est.h) * std::cos(est.lat));
  x.h = est.h + dx(2);
  x.v_N = est.v_N - dx.segment<3>(3);
  x.q_BtoN = (ins::quatFromRotVec(-dx.segment<3>(6)) * est.q_BtoN).normalized();
  return x;
}

}  // namespace navimpact::filter
