/**
 * @file earth.hpp
 * @brief WGS84 earth model for strapdown navigation in the local NED frame:
 *        normal gravity, Earth rate, radii of curvature, transport rate and
 *        geodetic <-> ECEF <-> local NED conversions (via GeographicLib).
 *
 * Conventions: angles in radians, heights ellipsoidal in metres, navigation
 * frame N = local north-east-down at the point, E = ECEF (WGS84).
 * Equation numbers refer to Groves 2013 (Principles of GNSS, Inertial, and
 * Multisensor Integrated Navigation Systems, 2nd ed.).
 */
#pragma once

#include <Eigen/Core>

namespace navimpact::earth {

constexpr double kA = 6378137.0;                  ///< WGS84 semi-major axis [m]
constexpr double kF = 1.0 / 298.257223563;        ///< WGS84 flattening [-]
constexpr double kE2 = kF * (2.0 - kF);           ///< first eccentricity squared [-]
constexpr double kOmegaIE = 7.292115e-5;          ///< Earth rotation rate [rad/s] (Groves 2.133)
constexpr double kGM = 3.986004418e14;            ///< WGS84 gravitational constant [m^3/s^2]

/// Geodetic position: latitude, longitude [rad], ellipsoidal height [m].
struct Geodetic {
  double lat = 0.0;  ///< latitude [rad], in [-pi/2, pi/2]
  double lon = 0.0;  ///< longitude [rad], any value (not wrapped)
  double h = 0.0;    ///< height above the WGS84 ellipsoid [m]
};

/// Radii of curvature of the ellipsoid.
struct Radii {
  double R_N = 0.0;  ///< meridian radius R_N [m] (Groves 2.105)
  double R_E = 0.0;  ///< transverse (prime vertical) radius R_E [m] (Groves 2.106)
  double dR_N_dlat = 0.0;  ///< derivative of R_N w.r.t. latitude [m/rad]
  double dR_E_dlat = 0.0;  ///< derivative of R_E w.r.t. latitude [m/rad]
};

/**
 * Meridian and transverse radii of curvature.
 * @param[in] lat  geodetic latitude [rad], in [-pi/2, pi/2].
 */
Radii radii(double lat);

/**
 * WGS84 normal gravity (gravitation plus centrifugal) resolved in NED at
 * (lat, h), from GeographicLib::NormalGravity::WGS84(); the north component
 * is the small deflection of normal gravity above the ellipsoid (0 at h = 0),
 * east is 0.
 * @param[in] lat  geodetic latitude [rad].
 * @param[in] h    ellipsoidal height [m], |h| < 1e5 for meaningful results.
 * @return g_N [m/s^2], down component positive.
 */
Eigen::Vector3d gravity_N(double lat, double h);

/**
 * WGS84 normal gravity for a moving vehicle, at a fraction of the cost of
 * gravity_N(): the GeographicLib field is evaluated at a reference point
 * (lat0, h0) together with its latitude and height derivatives (central
 * differences of gravity_N, steps 1e-5 rad and 1 m), and used to first order
 * within a box around it; outside the box the reference point moves to the
 * query point. With the default box (|h - h0| <= 10 m, |lat - lat0| <= 1e-4
 * rad, about 640 m) the neglected second-order terms are below 1e-9 m/s^2
 * (d2g/dh2 = 6 g/a^2 = 1.4e-12 s^-2/m, d2g/dlat2 < 0.11 m/s^2/rad^2), i.e.
 * 1e-10 g, far below any IMU's bias. Longitude does not enter normal gravity.
 * Not thread-safe (one instance per navigation loop).
 */
class LocalGravity {
 public:
  /**
   * @param[in] max_dh_m      half-size of the box in height [m], > 0.
   * @param[in] max_dlat_rad  half-size of the box in latitude [rad], > 0.
   */
  explicit LocalGravity(double max_dh_m = 10.0, double max_dlat_rad = 1e-4)
      : max_dh_(max_dh_m), max_dlat_(max_dlat_rad) {}

  /**
   * Normal gravity in NED at (lat, h), as gravity_N() to within the bound above.
   * @param[in] lat  geodetic latitude [rad], |lat| < pi/2 - 1e-4.
   * @param[in] h    ellipsoidal height [m], |h| < 1e5.
   * @return g_N [m/s^2], down component positive.
   */
  Eigen::Vector3d operator()(double lat, double h);

  /// Number of times the reference point was (re)computed (5 gravity_N calls each).
  long refreshes() const { return refreshes_; }

 private:
  double max_dh_, max_dlat_;
  bool valid_ = false;
  double lat0_ = 0.0, h0_ = 0.0;
  Eigen::Vector3d g0_ = Eigen::Vector3d::Zero(), dg_dlat_ = Eigen::Vector3d::Zero(),
                  dg_dh_ = Eigen::Vector3d::Zero();
  long refreshes_ = 0;
};

/**
 * Partial derivatives of the down component of normal gravity, for error
 * models (Somigliana's formula differentiated, and the free-air gradient of
 * Heiskanen & Moritz 1967 eq. 2-124).
 * @param[in] lat  geodetic latitude [rad].
 * @param[in] h    ellipsoidal height [m].
 * @param[out] dgD_dlat  d g_D / d lat [m/s^2/rad].
 * @param[out] dgD_dh    d g_D / d h [1/s^2] (negative: gravity weakens upwards).
 */
void gravityGradient(double lat, double h, double& dgD_dlat, double& dgD_dh);

/**
 * Earth rotation resolved in NED, omega_IE_N = Omega [cos lat, 0, -sin lat]
 * (Groves 5.41).
 * @param[in] lat  geodetic latitude [rad].
 * @return [rad/s].
 */
Eigen::Vector3d w_IE_N(double lat);

/**
 * Transport rate, the turn rate of NED with respect to ECEF (Groves 5.44).
 * @param[in] lat  geodetic latitude [rad], |lat| < pi/2 (singular at the poles).
 * @param[in] h    ellipsoidal height [m].
 * @param[in] v_N  velocity w.r.t. the Earth resolved in NED [m/s].
 * @return omega_EN_N [rad/s].
 */
Eigen::Vector3d w_EN_N(double lat, double h, const Eigen::Vector3d& v_N);

/**
 * The trigonometry of one latitude and its radii, computed once for the
 * functions above (the mechanization meets each latitude several times per
 * step). Every value is the same as from the function of the latitude:
 * radii(l) == radii(l.lat), w_IE_N(l) == w_IE_N(l.lat),
 * w_EN_N(l, h, v) == w_EN_N(l.lat, h, v), bit for bit.
 */
struct LatitudeTerms {
  explicit LatitudeTerms(double lat);
  double lat;     ///< [rad]
  double sin_lat, cos_lat, tan_lat;
  Radii r;
};
Eigen::Vector3d w_IE_N(const LatitudeTerms& l);
Eigen::Vector3d w_EN_N(const LatitudeTerms& l, double h, const Eigen::Vector3d& v_N);
/// gravityGradient() with the sine of l.lat taken from @p l (the same values).
void gravityGradient(const LatitudeTerms& l, double h, double& dgD_dlat, double& dgD_dh);

/**
 * Rotation matrix from ECEF to NED at (lat, lon) (Groves 2.150 transposed).
 * @param[in] lat, lon  geodetic latitude and longitude [rad].
 */
Eigen::Matrix3d C_EtoN(double lat, double lon);

/// Geodetic -> ECEF [m] (GeographicLib::Geocentric::WGS84()).
Eigen::Vector3d geodeticToEcef(const Geodetic& p);

/// ECEF [m] -> geodetic (exact, GeographicLib).
Geodetic ecefToGeodetic(const Eigen::Vector3d& r_E);

/**
 * Local Cartesian NED coordinates of @p p in the tangent frame at @p origin
 * (GeographicLib::LocalCartesian gives ENU; converted to NED here).
 * @return [north, east, down] [m].
 */
Eigen::Vector3d geodeticToNed(const Geodetic& origin, const Geodetic& p);

/// Inverse of geodeticToNed(): local NED [m] at @p origin -> geodetic.
Geodetic nedToGeodetic(const Geodetic& origin, const Eigen::Vector3d& ned);

/**
 * Small position difference a - b in metres along local N, E, D at b, using
 * the curvilinear relations (Groves 2.119): dN = (R_N+h) dlat,
 * dE = (R_E+h) cos(lat) dlon, dD = -dh. Accurate for differences of a few km.
 */
Eigen::Vector3d curvilinearDiffNed(const Geodetic& a, const Geodetic& b);

}  // namespace navimpact::earth
