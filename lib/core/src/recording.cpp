// Physical ranges of a recording's records (see recording.hpp).
#include "navimpact/core/recording.hpp"

#include <algorithm>
#include <cmath>

#include "navimpact/core/format.hpp"
#include "navimpact/core/imu_series.hpp"

namespace navimpact {

namespace {

std::string g(double v) { return formatNumber(v, 6); }

/// "" if every component of @p v is finite with |v_i| <= lim, else the first that is not.
std::string componentsWithin(const Eigen::Vector3d& v, double lim, const char* what, const char* unit,
                             const char* hint, bool ned = false) {
  static const char* body[] = {"x", "y", "z"};
  static const char* nav[] = {"north", "east", "down"};
  const char* const* axis = ned ? nav : body;
  for (int i = 0; i < 3; ++i)
    if (!(std::abs(v(i)) <= lim))
      return std::string(what) + " " + axis[i] + " = " + g(v(i)) + " " + unit + " is beyond any " + hint + " (|value| <= " +
             g(lim) + " " + unit + ")";
  return "";
}

std::string heightWithin(double h, const char* what) {
  if (h >= kMinHeightM && h <= kMaxHeightM) return "";
  return std::string(what) + " " + g(h) + " m is outside [" + g(kMinHeightM) + ", " + g(kMaxHeightM) + "] m";
}

std::string sigmaWithin(double s, const char* what, const char* unit) {
  if (s >= kMinRecordSigma && s <= kMaxRecordSigma) return "";
  return std::string(what) + " " + g(s) + " " + unit + " is outside [" + g(kMinRecordSigma) + ", " + g(kMaxRecordSigma) +
         "] " + unit;
}

/// "" if the diagonal of @p c holds variances whose square roots lie in the sigma range.
std::string covarianceWithin(const Eigen::Matrix3d& c, const char* what, const char* unit) {
  if (!c.allFinite()) return std::string(what) + " covariance is not finite";
  for (int i = 0; i < 3; ++i)
    if (auto p = sigmaWithin(std::sqrt(std::max(c(i, i), 0.0)), what, unit); !p.empty()) return p;
  return "";
}

std::string sigmasWithin(const Eigen::Vector3d& s, const char* what, const char* unit) {
  for (int i = 0; i < 3; ++i)
    if (auto p = sigmaWithin(s(i), what, unit); !p.empty()) return p;
  return "";
}

}  // namespace

std::string recordProblem(const ImuRecord& r) {
  if (auto p = componentsWithin(r.w_IB_B, kMaxAbsAngularRate, "angular rate", "rad/s", "IMU"); !p.empty()) return p;
  return componentsWithin(r.f_B, kMaxAbsSpecificForce, "specific force", "m/s^2", "IMU");
}

std::string recordProblem(const GnssFix& r) {
  if (!(std::abs(r.pos.lat) <= M_PI / 2) || !(std::abs(r.pos.lon) <= 2 * M_PI))
    return "GNSS position is not a place on Earth (latitude " + g(r.pos.lat) + " rad, longitude " + g(r.pos.lon) + " rad)";
  if (auto p = heightWithin(r.pos.h, "GNSS height"); !p.empty()) return p;
  if (r.v_N)
    if (auto p = componentsWithin(*r.v_N, kMaxAbsSpeedMps, "GNSS velocity", "m/s", "vehicle", true); !p.empty()) return p;
  if (r.cov_pos_N)
    if (auto p = covarianceWithin(*r.cov_pos_N, "GNSS position sigma", "m"); !p.empty()) return p;
  if (r.cov_vel_N)
    if (auto p = covarianceWithin(*r.cov_vel_N, "GNSS velocity sigma", "m/s"); !p.empty()) return p;
  return "";
}

std::string recordProblem(const BaroSample& r) {
  if (auto p = heightWithin(r.h, "barometric height"); !p.empty()) return p;
  if (r.sigma_m) return sigmaWithin(*r.sigma_m, "barometric height sigma", "m");
  return "";
}

std::string recordProblem(const ReferenceRecord& r) {
  // the tangent-plane position: within an Earth radius of the origin
  if (auto p = componentsWithin(r.p_L, 1.0e7, "reference position", "m", "place near the origin", true);
      !p.empty())
    return p;
  if (r.v_N)
    if (auto p = componentsWithin(*r.v_N, kMaxAbsSpeedMps, "reference velocity", "m/s", "vehicle", true); !p.empty()) return p;
  if (r.q_BtoN && !(std::abs(r.q_BtoN->norm() - 1.0) <= 1e-6))
    return "reference attitude quaternion has norm " + g(r.q_BtoN->norm()) + " (a rotation has norm 1)";
  if (r.sigma_p_L)
    if (auto p = sigmasWithin(*r.sigma_p_L, "reference position sigma", "m"); !p.empty()) return p;
  if (r.sigma_v_N)
    if (auto p = sigmasWithin(*r.sigma_v_N, "reference velocity sigma", "m/s"); !p.empty()) return p;
  if (r.sigma_att)
    for (int i = 0; i < 3; ++i)
      if (!(r.sigma_att->coeff(i) > 0.0 && r.sigma_att->coeff(i) <= M_PI))
        return "reference attitude sigma " + g(r.sigma_att->coeff(i)) + " rad is outside (0, pi] rad";
  return "";
}

double nominalStep(const std::vector<double>& steps) {
  if (steps.empty()) return 0.0;
  std::vector<double> sorted = steps;
  const auto mid = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
  std::nth_element(sorted.begin(), mid, sorted.end());
  const double med = *mid;
  if (!(med > 0.0)) return med;
  double sum = 0.0;
  std::size_t n = 0;
  for (double h : steps)
    if (h > 0.0 && h < 1.75 * med) {  // between quantised steps (<= 1.5 medians) and one lost sample (2)
      sum += h;
      ++n;
    }
  const double mean = sum / static_cast<double>(n);  // n >= 1: the median itself counts
  return std::abs(mean - med) > 0.01 * med ? mean : med;
}

}  // namespace navimpact
