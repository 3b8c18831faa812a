// Time and frame conventions shared by the rawlog writer and readers (internal to lib/rawlog).
#pragma once

#include <Eigen/Core>

#include <cstring>

namespace navimpact::rawlog::detail {

constexpr double kTick = 1e-7;  ///< MRPT Clock resolution [s]

/// The reference as a pose observation in MRPT's conventions: map frame ENU at
/// the origin (x east, y north, z up), vehicle frame x forward, y left, z up.
/// T_NtoENU maps NED to ENU; T_FLUtoFRD maps FLU to FRD (both are their own inverse).
inline const Eigen::Matrix3d& T_NtoENU() {
  static const Eigen::Matrix3d T = (Eigen::Matrix3d() << 0, 1, 0, 1, 0, 0, 0, 0, -1).finished();
  return T;
}
inline const Eigen::Matrix3d& T_FLUtoFRD() {
  static const Eigen::Matrix3d T = Eigen::Vector3d(1, -1, -1).asDiagonal();
  return T;
}
/// Attitude variance that stands for "no attitude known" (sigma 1e6 rad).
constexpr double kUnknownAttitudeVar = 1e12;

/// The byte MRPT stored in a bool it deserialises byte for byte (the presence
/// flags of CObservationIMU; Message_TOPCON_PZS hasCartesianPosVel, hasPosCov,
/// hasVelCov). Reading a stored 255 as a bool is undefined behaviour (found by
/// the libFuzzer runs of rawlog), so every such flag of a read entry goes
/// through this.
inline unsigned char storedByte(const bool& b) {
  unsigned char c = 0;
  std::memcpy(&c, &b, 1);
  return c;
}
/// Such a flag as a bool: any byte but 0 is true.
inline bool storedTrue(const bool& b) { return storedByte(b) != 0; }

}  // namespace navimpact::rawlog::detail
