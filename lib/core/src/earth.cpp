// WGS84 earth model (Groves 2013 ch. 2 and 5) on top of GeographicLib.
#include "navimpact/core/earth.hpp"

#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/NormalGravity.hpp>

#include <cmath>

namespace navimpact::earth {
namespace {
constexpr double kRad2Deg = 180.0 / 3.14159265358979323846;
constexpr double kDeg2Rad = 3.14159265358979323846 / 180.0;
}  // namespace

namespace {
Radii radiiOf(double s, double c) {
  const double w2 = 1.0 - kE2 * s * s;
  const double w = std::sqrt(w2);
  Radii r;
  r.R_N = kA * (1.0 - kE2) / (w2 * w);  // Groves 2.105
  r.R_E = kA / w;                       // Groves 2.106
  // d/dlat of w2^(-3/2) and w2^(-1/2): w2' = -2 e2 s c.
  r.dR_N_dlat = r.R_N * 3.0 * kE2 * s * c / w2;
  r.dR_E_dlat = r.R_E * kE2 * s * c / w2;
  return r;
}
}  // namespace

Radii radii(double lat) { return radiiOf(std::sin(lat), std::cos(lat)); }

LatitudeTerms::LatitudeTerms(double latitude)
    : lat(latitude), sin_lat(std::sin(latitude)), cos_lat(std::cos(latitude)), tan_lat(sin_lat / cos_lat),
      r(radiiOf(sin_lat, cos_lat)) {}

Eigen::Vector3d gravity_N(double lat, double h) {
  static const GeographicLib::NormalGravity& ng = GeographicLib::NormalGravity::WGS84();
  double gy = 0.0, gz = 0.0;  // northerly and upward components
  ng.Gravity(lat * kRad2Deg, h, gy, gz);
  return Eigen::Vector3d(gy, 0.0, -gz);
}

Eigen::Vector3d LocalGravity::operator()(double lat, double h) {
  if (!valid_ || std::abs(h - h0_) > max_dh_ || std::abs(lat - lat0_) > max_dlat_) {
    // Reference point and its derivatives by central differences of the
    // GeographicLib field (truncation error of order step^2 x third derivative,
    // below 1e-15 m/s^2 over the box).
    constexpr double kDlat = 1e-5, kDh = 1.0;
    lat0_ = lat;
    h0_ = h;
    g0_ = gravity_N(lat, h);
    dg_dlat_ = (gravity_N(lat + kDlat, h) - gravity_N(lat - kDlat, h)) / (2.0 * kDlat);
    dg_dh_ = (gravity_N(lat, h + kDh) - gravity_N(lat, h - kDh)) / (2.0 * kDh);
    valid_ = true;
    ++refreshes_;
    return g0_;
  }
  return g0_ + dg_dlat_ * (lat - lat0_) + dg_dh_ * (h - h0_);
}

namespace {
void gravityGradientOf(double lat, double s, double h, double& dgD_dlat, double& dgD_dh) {
  static const GeographicLib::NormalGravity& ng = GeographicLib::NormalGravity::WGS84();
  // Somigliana: gamma = gamma_e (1 + k s2) / sqrt(1 - e2 s2), k = b gamma_p / (a gamma_e) - 1.
  static const double ge = ng.SurfaceGravity(0.0), gp = ng.SurfaceGravity(90.0);
  static const double b = kA * (1.0 - kF);
  static const double k = b * gp / (kA * ge) - 1.0;
  static const double m = kOmegaIE * kOmegaIE * kA * kA * b / kGM;
  const double s2 = s * s;
  const double w2 = 1.0 - kE2 * s2;
  const double dgamma_ds2 = ge * (k / std::sqrt(w2) + (1.0 + k * s2) * 0.5 * kE2 / (w2 * std::sqrt(w2)));
  const double gamma0 = ge * (1.0 + k * s2) / std::sqrt(w2);
  dgD_dlat = dgamma_ds2 * std::sin(2.0 * lat);
  // Free-air gradient (Heiskanen & Moritz 1967 eq. 2-124), first order in h.
  dgD_dh = -2.0 * gamma0 / kA * (1.0 + kF + m - 2.0 * kF * s2) + 6.0 * gamma0 * h / (kA * kA);
}
}  // namespace

void gravityGradient(double lat, double h, double& dgD_dlat, double& dgD_dh) {
  gravityGradientOf(lat, std::sin(lat), h, dgD_dlat, dgD_dh);
}

void gravityGradient(const LatitudeTerms& l, double h, double& dgD_dlat, double& dgD_dh) {
  gravityGradientOf(l.lat, l.sin_lat, h, dgD_dlat, dgD_dh);
}

namespace {
Eigen::Vector3d w_IE_Nof(double s, double c) {
  return Eigen::Vector3d(kOmegaIE * c, 0.0, -kOmegaIE * s);  // Groves 5.41
}
Eigen::Vector3d w_EN_Nof(const Radii& r, double t, double h, const Eigen::Vector3d& v_N) {
  return Eigen::Vector3d(v_N.y() / (r.R_E + h), -v_N.x() / (r.R_N + h),
                         -v_N.y() * t / (r.R_E + h));  // Groves 5.44
}
}  // namespace

Eigen::Vector3d w_IE_N(double lat) { return w_IE_Nof(std::sin(lat), std::cos(lat)); }
Eigen::Vector3d w_IE_N(const LatitudeTerms& l) { return w_IE_Nof(l.sin_lat, l.cos_lat); }

Eigen::Vector3d w_EN_N(double lat, double h, const Eigen::Vector3d& v_N) {
  return w_EN_Nof(radii(lat), std::sin(lat) / std::cos(lat), h, v_N);
}
Eigen::Vector3d w_EN_N(const LatitudeTerms& l, double h, const Eigen::Vector3d& v_N) {
  return w_EN_Nof(l.r, l.tan_lat, h, v_N);
}

Eigen::Matrix3d C_EtoN(double lat, double lon) {
  const double sl = std::sin(lat), cl = std::cos(lat), so = std::sin(lon), co = std::cos(lon);
  Eigen::Matrix3d C;  // Groves 2.150
  C << -sl * co, -sl * so, cl,
       -so, co, 0.0,
       -cl * co, -cl * so, -sl;
  return C;
}

Eigen::Vector3d geodeticToEcef(const Geodetic& p) {
  Eigen::Vector3d r;
  GeographicLib::Geocentric::WGS84().Forward(p.lat * kRad2Deg, p.lon * kRad2Deg, p.h, r.x(),
                                             r.y(), r.z());
  return r;
}

Geodetic ecefToGeodetic(const Eigen::Vector3d& r_E) {
  Geodetic p;
  GeographicLib::Geocentric::WGS84().Reverse(r_E.x(), r_E.y(), r_E.z(), p.lat, p.lon, p.h);
  p.lat *= kDeg2Rad;
  p.lon *= kDeg2Rad;
  return p;
}

Eigen::Vector3d geodeticToNed(const Geodetic& origin, const Geodetic& p) {
  GeographicLib::LocalCartesian lc(origin.lat * kRad2Deg, origin.lon * kRad2Deg, origin.h);
  double e = 0, n = 0, u = 0;
  lc.Forward(p.lat * kRad2Deg, p.lon * kRad2Deg, p.h, e, n, u);
  return Eigen::Vector3d(n, e, -u);  // ENU -> NED
}

Geodetic nedToGeodetic(const Geodetic& origin, const Eigen::Vector3d& ned) {
  GeographicLib::LocalCartesian lc(origin.lat * kRad2Deg, origin.lon * kRad2Deg, origin.h);
  Geodetic p;
  lc.Reverse(ned.y(), ned.x(), -ned.z(), p.lat, p.lon, p.h);
  p.lat *= kDeg2Rad;
  p.lon *= kDeg2Rad;
  return p;
}

Eigen::Vector3d curvilinearDiffNed(const Geodetic& a, const Geodetic& b) {
  const Radii r = radii(b.lat);
  double dlon = std::remainder(a.lon - b.lon, 2.0 * 3.14159265358979323846);
  return Eigen::Vector3d((r.R_N + b.h) * (a.lat - b.lat), (r.R_E + b.h) * std::cos(b.lat) * dlon,
                         -(a.h - b.h));  // Groves 2.119
}

}  // namespace navimpact::earth
