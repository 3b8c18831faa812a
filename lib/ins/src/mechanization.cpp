// Local-navigation-frame strapdown mechanization, Groves 2013 §5.4-5.5.
#include "navimpact/ins/mechanization.hpp"

#include <cmath>
#include <cstring>

namespace navimpact::ins {

using Eigen::Vector3d;

NavState mechanize(const NavState& prev, const ImuSample& cur, const ImuSample* last,
                   const MechanizationOptions& opt) {
  return mechanize(prev, cur, last, nullptr, opt);
}

NavState mechanize(const NavState& prev, const ImuSample& cur, const ImuSample* last,
                   const ImuSample* last2, const MechanizationOptions& opt,
                   earth::LocalGravity* gravity) {
  return mechanize(prev, cur, last, last2, opt, gravity, earth::LatitudeTerms(prev.lat), nullptr);
}

NavState mechanize(const NavState& prev, const ImuSample& cur, const ImuSample* last,
                   const ImuSample* last2, const MechanizationOptions& opt,
                   earth::LocalGravity* gravity, const earth::LatitudeTerms& L0,
                   std::optional<earth::LatitudeTerms>* L1_out) {
  const double tau = cur.dt;
  const Vector3d& a = cur.dtheta_B;  // alpha_IB_B
  const Vector3d& u = cur.dv_B;      // upsilon_IB_B

  // Coning and sculling from the previous intervals' increments. The
  // coefficients make 1/2 int (alpha(t) x omega(t)) dt (coning) and
  // 1/2 int (alpha x f + upsilon x omega) dt (sculling; the same bilinear form)
  // exact for rates polynomial in time over the samples used:
  //  - two-sample, rates linear in time: 1/12 x_{n-1} x y_n
  //    (Groves 2013 eq. 5.97-5.98; Savage 1998);
  //  - three-sample with the two previous intervals, rates quadratic in time:
  //    k1 = -1/24 on x_{n-2}, k2 = 1/6 on x_{n-1} (Ignagni 1996 class of
  //    previous-interval algorithms; derived by matching the a x b and a x c
  //    terms of omega(t) = a + b t + c t^2, see docs in the header).
  Vector3d a_c = a;
  Vector3d scul = Vector3d::Zero();
  if (opt.coning_sculling && last != nullptr) {
    double k1 = 0.0, k2 = 1.0 / 12.0;
    if (last2 != nullptr && std::abs(last2->dt - tau) <= 1e-9 * tau &&
        std::abs(last->dt - tau) <= 1e-9 * tau) {
      k1 = -1.0 / 24.0;
      k2 = 1.0 / 6.0;
      a_c += k1 * last2->dtheta_B.cross(a);
      scul += k1 * (last2->dtheta_B.cross(u) + last2->dv_B.cross(a));
    }
    a_c += k2 * last->dtheta_B.cross(a);
    scul += k2 * (last->dtheta_B.cross(u) + last->dv_B.cross(a));
  }

  // Velocity-increment rotation to the start-of-interval body frame, exact for
  // a constant rate over the interval (Groves 2013 eq. 5.84-5.85 with the full
  // series instead of the first-order 1/2 [alpha x] term):
  //   C_b(-)b(t) integrated = I + (1-cos|a|)/|a|^2 [a x] + (1 - sin|a|/|a|)/|a|^2 [a x]^2
  // Below |a| = 0.05 rad (every step but the fastest turns) their Taylor
  // series to |a|^6: the next terms are below 2e-17 relative, where the
  // closed forms lose ~1e-16 / |a|^2 to cancellation (4e-11 at 2.5 mrad).
  const double n2 = a.squaredNorm();
  double c1, c2;
  if (n2 < 2.5e-3) {
    c1 = 0.5 - n2 * (1.0 / 24.0 - n2 * (1.0 / 720.0 - n2 / 40320.0));
    c2 = 1.0 / 6.0 - n2 * (1.0 / 120.0 - n2 * (1.0 / 5040.0 - n2 / 362880.0));
  } else {
    const double n = std::sqrt(n2);
    c1 = (1.0 - std::cos(n)) / n2;
    c2 = (1.0 - std::sin(n) / n) / n2;
  }
  const Vector3d axu = a.cross(u);
  const Vector3d u_c = u + c1 * axu + c2 * a.cross(axu) + scul;

  // trigonometry and radii once per latitude (L0: prev.lat, given by the caller)
  const earth::Radii& r0 = L0.r;
  const Vector3d w_ie0 = earth::w_IE_N(L0);
  const Vector3d w_en0 = earth::w_EN_N(L0, prev.h, prev.v_N);
  const Eigen::Matrix3d C0 = prev.C_BtoN();

  // Specific-force frame transformation with the mean N-frame rotation (Groves 5.86).
  const Vector3d dv_f_N = C0 * u_c - 0.5 * (w_ie0 + w_en0).cross(C0 * u_c) * tau;

  // Velocity update (Groves 5.54) with gravity and Coriolis evaluated at the
  // interval midpoint (predicted, then corrected once).
  const Vector3d g0 = gravity ? (*gravity)(prev.lat, prev.h) : earth::gravity_N(prev.lat, prev.h);
  Vector3d v1 = prev.v_N + dv_f_N + (g0 - (2.0 * w_ie0 + w_en0).cross(prev.v_N)) * tau;
  {
    const Vector3d v_mid = 0.5 * (prev.v_N + v1);
    const double h_mid = prev.h - 0.5 * tau * v_mid.z();
    const double lat_mid = prev.lat + 0.5 * tau * v_mid.x() / (r0.R_N + h_mid);
    const Vector3d g_mid = gravity ? (*gravity)(lat_mid, h_mid) : earth::gravity_N(lat_mid, h_mid);
    const earth::LatitudeTerms Lmid(lat_mid);
    const Vector3d w_ie_mid = earth::w_IE_N(Lmid);
    const Vector3d w_en_mid = earth::w_EN_N(Lmid, h_mid, v_mid);
    v1 = prev.v_N + dv_f_N + (g_mid - (2.0 * w_ie_mid + w_en_mid).cross(v_mid)) * tau;
  }

  // Position update, trapezoidal (Groves 5.56).
  NavState x;
  x.t = cur.t;
  x.h = prev.h - 0.5 * tau * (prev.v_N.z() + v1.z());
  x.lat = prev.lat + 0.5 * tau * (prev.v_N.x() / (r0.R_N + prev.h) + v1.x() / (r0.R_N + x.h));
  const earth::LatitudeTerms L1(x.lat);
  const earth::Radii& r1 = L1.r;
  x.lon = prev.lon + 0.5 * tau * (prev.v_N.y() / ((r0.R_E + prev.h) * L0.cos_lat) +
                                  v1.y() / ((r1.R_E + x.h) * L1.cos_lat));
  x.v_N = v1;

  // Attitude update: body rotation (corrected increment) and N-frame rotation
  // over the interval with the mean omega_IN (Groves 5.73 in quaternion form).
  const double lat_m = 0.5 * (prev.lat + x.lat), h_m = 0.5 * (prev.h + x.h);
  const earth::LatitudeTerms Lm(lat_m);
  const Vector3d w_in_mid = earth::w_IE_N(Lm) + earth::w_EN_N(Lm, h_m, 0.5 * (prev.v_N + v1));
  x.q_BtoN = (quatFromRotVec(-w_in_mid * tau) * prev.q_BtoN * quatFromRotVec(a_c)).normalized();
  if (L1_out) L1_out->emplace(L1);
  return x;
}

void Mechanization::step(const ImuSample& s) {
  // the latitude terms of the end of the last step serve this one unless the
  // state was changed in between (a filter update, setState)
  // (compared bit for bit: sin(-0) is -0)
  if (!lat_terms_ || std::memcmp(&lat_terms_->lat, &x_.lat, sizeof(double)) != 0) lat_terms_.emplace(x_.lat);
  x_ = mechanize(x_, s, has_last_ ? &last_ : nullptr, has_last2_ ? &last2_ : nullptr, opt_, &gravity_,
                 *lat_terms_, &lat_terms_);
  if (has_last_) {
    last2_ = last_;
    has_last2_ = true;
  }
  last_ = s;
  has_last_ = true;
}

}  // namespace navimpact::ins
