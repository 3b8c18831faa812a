// Rawlog writer of navimpact::Recording (see writer.hpp; the reader is rawlog_reader.cpp).
#include "navimpact/rawlog/writer.hpp"

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CObservationComment.h>
#include <mrpt/obs/CObservationGPS.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/serialization/CArchive.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <stdexcept>
#include <vector>

#include "frames.hpp"
#include "gz_member_sink.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/imu_series.hpp"

namespace navimpact::rawlog {

using mrpt::obs::CObservationIMU;
namespace gnss = mrpt::obs::gnss;

namespace {

using detail::kTick;
using detail::kUnknownAttitudeVar;
using detail::T_FLUtoFRD;
using detail::T_NtoENU;

mrpt::Clock::time_point stamp(long long startUnix, double tRel) {
  const auto base = mrpt::Clock::fromDouble(static_cast<double>(startUnix));
  return base + mrpt::Clock::duration(std::llround(tRel / kTick));
}

struct Entry {
  double t;
  int order;  // tie-break: GT 0, IMU 1, BARO 2, GNSS 3
  std::size_t index;
  int block;  // 0: a record pending from an earlier block, 1: of this block
};

Eigen::Matrix4f cov4(const Eigen::Matrix3d& c) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Zero();
  m.topLeftCorner<3, 3>() = c.cast<float>();
  return m;
}

}  // namespace

struct RawlogWriter::Impl {
  std::string path;
  detail::GzMemberSink out;
  mrpt::serialization::CArchiveStreamBase<mrpt::io::CStream> arch;
  long long su = 0;
  double t_start_s = 0.0;
  Recording pending;  // records not yet written (their time may tie with a later block's)
  CObservationIMU imu, baro, gtVel;
  mrpt::obs::CObservationRobotPose gt;
  mrpt::obs::CObservationGPS gps;
  bool closed = false;

  Impl(const std::string& p, int level) : path(p), out(p, level), arch(out) {}
  void write(const Recording& d, const Entry& e);
};

RawlogWriter::RawlogWriter(const std::string& path, const Recording& d, const RawlogWriteOptions& opt)
    // gzip members compressed on worker threads (see gz_member_sink.hpp)
    : impl_(std::make_unique<Impl>(path, opt.gzip ? std::clamp(opt.gzip_level, 1, 9) : 0)) {
  Impl& w = *impl_;
  w.su = d.start_unix_s;
  w.t_start_s = d.t_start_s;
  {
    mrpt::obs::CObservationComment c;
    c.sensorLabel = "SCENARIO";
    c.timestamp = stamp(w.su, 0.0);
    c.text = d.metadata;
    w.arch << c;
    if (!w.out.failure().empty()) throw Error(w.out.failure());
  }
  w.imu.sensorLabel = "IMU";
  {  // the values are body FRD: the IMU's mounting in MRPT's vehicle frame (x forward, y left, z up)
    // is a half turn about x, written exactly (readers that apply sensorPose get FLU values)
    mrpt::math::CMatrixDouble33 rot;
    rot.setZero();
    rot(0, 0) = 1.0;
    rot(1, 1) = -1.0;
    rot(2, 2) = -1.0;
    mrpt::math::CVectorFixedDouble<3> zero;
    zero[0] = zero[1] = zero[2] = 0.0;
    w.imu.sensorPose = mrpt::poses::CPose3D(rot, zero);
  }
  w.baro.sensorLabel = "BARO";
  w.gtVel.sensorLabel = "GT_VEL";
  w.gt.sensorLabel = "GT";
  w.gps.sensorLabel = "GNSS";
  w.gps.has_satellite_timestamp = false;
  if (d.lever_arm_B) {  // antenna on the vehicle, MRPT vehicle frame FLU
    const Eigen::Vector3d l = T_FLUtoFRD() * *d.lever_arm_B;
    w.gps.sensorPose = mrpt::poses::CPose3D(l[0], l[1], l[2], 0, 0, 0);
  }
}

RawlogWriter::~RawlogWriter() = default;

void RawlogWriter::append(const Recording& block, double complete_until_s) {
  Impl& w = *impl_;
  if (w.closed) throw Error(w.path + ": rawlog already closed");
  // Entries of what is pending (first: earlier records of each stream) and of the block, in
  // time order (equal times: GT, IMU, BARO, GNSS; one stream's records keep their order).
  const Recording* src[2] = {&w.pending, &block};
  std::vector<Entry> order;
  order.reserve(w.pending.imu.size() + w.pending.gnss.size() + w.pending.baro.size() + w.pending.reference.size() +
                block.imu.size() + block.gnss.size() + block.baro.size() + block.reference.size());
  for (int b = 0; b < 2; ++b) {
    const Recording& d = *src[b];
    for (std::size_t i = 0; i < d.reference.size(); ++i) order.push_back({d.reference[i].t, 0, i, b});
    for (std::size_t i = 0; i < d.imu.size(); ++i) order.push_back({d.imu[i].t, 1, i, b});
    for (std::size_t i = 0; i < d.baro.size(); ++i) order.push_back({d.baro[i].t, 2, i, b});
    for (std::size_t i = 0; i < d.gnss.size(); ++i) order.push_back({d.gnss[i].t, 3, i, b});
  }
  std::stable_sort(order.begin(), order.end(), [](const Entry& a, const Entry& b) {
    const auto ta = std::llround(a.t / kTick), tb = std::llround(b.t / kTick);
    if (ta != tb) return ta < tb;
    if (a.order != b.order) return a.order < b.order;
    return a.block < b.block;  // pending first: they came before
  });
  // An entry is written when no later record can sort before it: later records have
  // times > complete_until_s, hence ticks >= its tick.
  const bool all = !(complete_until_s < std::numeric_limits<double>::infinity());
  const long long limit = all ? 0 : std::llround(complete_until_s / kTick);
  Recording keep;
  for (const Entry& e : order) {
    if (all || std::llround(e.t / kTick) < limit) {
      w.write(*src[e.block], e);
      continue;
    }
    const Recording& d = *src[e.block];
    switch (e.order) {
      case 0: keep.reference.push_back(d.reference[e.index]); break;
      case 1: keep.imu.push_back(d.imu[e.index]); break;
      case 2: keep.baro.push_back(d.baro[e.index]); break;
      default: keep.gnss.push_back(d.gnss[e.index]); break;
    }
  }
  w.pending.imu.swap(keep.imu);
  w.pending.gnss.swap(keep.gnss);
  w.pending.baro.swap(keep.baro);
  w.pending.reference.swap(keep.reference);
  if (!w.out.failure().empty()) throw Error(w.out.failure());  // a full disk (gz_member_sink.hpp)
}

void RawlogWriter::close() {
  Impl& w = *impl_;
  if (w.closed) return;
  append(Recording{}, std::numeric_limits<double>::infinity());
  w.closed = true;
  w.out.close();
  if (!std::filesystem::exists(w.path)) throw Error(w.path + ": rawlog was not written");
}

void RawlogWriter::Impl::write(const Recording& d, const Entry& e) {
  const auto ts = stamp(su, e.t - t_start_s);
  if (e.order == 1) {
    const auto& r = d.imu[e.index];
    imu.timestamp = ts;
    imu.set(mrpt::obs::IMU_WX, r.w_IB_B[0]);
    imu.set(mrpt::obs::IMU_WY, r.w_IB_B[1]);
    imu.set(mrpt::obs::IMU_WZ, r.w_IB_B[2]);
    imu.set(mrpt::obs::IMU_X_ACC, r.f_B[0]);
    imu.set(mrpt::obs::IMU_Y_ACC, r.f_B[1]);
    imu.set(mrpt::obs::IMU_Z_ACC, r.f_B[2]);
    arch << imu;
  } else if (e.order == 2) {
    baro.timestamp = ts;
    baro.set(mrpt::obs::IMU_ALTITUDE, d.baro[e.index].h);
    arch << baro;
  } else if (e.order == 0) {
    const auto& r = d.reference[e.index];
    gt.timestamp = ts;
    const Eigen::Vector3d p = T_NtoENU() * r.p_L;
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    if (r.q_BtoN) R = T_NtoENU() * r.q_BtoN->normalized().toRotationMatrix() * T_FLUtoFRD();
    mrpt::math::CMatrixDouble33 rot;
    mrpt::math::CVectorFixedDouble<3> xyz;
    for (int a = 0; a < 3; ++a) {
      xyz[a] = p[a];
      for (int b = 0; b < 3; ++b) rot(a, b) = R(a, b);
    }
    gt.pose.mean = mrpt::poses::CPose3D(rot, xyz);
    gt.pose.cov.setZero();  // zero: no sigma given
    if (r.sigma_p_L) {
      const Eigen::Vector3d s = T_NtoENU() * *r.sigma_p_L;
      for (int a = 0; a < 3; ++a) gt.pose.cov(a, a) = std::abs(s[a]) * std::abs(s[a]);
    }
    // angles in MRPT's order yaw, pitch, roll (about D, E, N for a level vehicle)
    for (int a = 0; a < 3; ++a)
      gt.pose.cov(3 + a, 3 + a) = !r.q_BtoN ? kUnknownAttitudeVar
                                  : r.sigma_att ? (*r.sigma_att)[2 - a] * (*r.sigma_att)[2 - a]
                                                : 0.0;
    arch << gt;
    if (r.v_N) {  // MRPT's pose observation has no velocity: a companion entry, same time
      gtVel.timestamp = ts;
      gtVel.dataIsPresent.fill(false);
      gtVel.set(mrpt::obs::IMU_X_VEL, (*r.v_N)[0]);
      gtVel.set(mrpt::obs::IMU_Y_VEL, (*r.v_N)[1]);
      gtVel.set(mrpt::obs::IMU_Z_VEL, (*r.v_N)[2]);
      arch << gtVel;
    }
  } else {
    const auto& f = d.gnss[e.index];
    gps.timestamp = ts;
    gps.originalReceivedTimestamp = ts;
    gps.messages.clear();
    const double tu = static_cast<double>(su) + (e.t - t_start_s);
    const double daySec = std::fmod(tu, 86400.0);
    gnss::Message_NMEA_GGA gga;
    gga.fields.UTCTime.hour = static_cast<uint8_t>(daySec / 3600.0);
    gga.fields.UTCTime.minute = static_cast<uint8_t>(std::fmod(daySec, 3600.0) / 60.0);
    gga.fields.UTCTime.sec = std::fmod(daySec, 60.0);
    gga.fields.latitude_degrees = f.pos.lat * 180.0 / M_PI;
    gga.fields.longitude_degrees = f.pos.lon * 180.0 / M_PI;
    gga.fields.fix_quality = 1;
    gga.fields.altitude_meters = f.pos.h;
    gga.fields.geoidal_distance = 0.0;
    gga.fields.orthometric_altitude = f.pos.h;
    gga.fields.corrected_orthometric_altitude = f.pos.h;
    gga.fields.satellitesUsed = 10;
    gga.fields.thereis_HDOP = true;
    gga.fields.HDOP = 1.0f;
    gps.setMsg(gga);
    gnss::Message_TOPCON_PZS pzs;
    pzs.latitude_degrees = gga.fields.latitude_degrees;
    pzs.longitude_degrees = gga.fields.longitude_degrees;
    pzs.height_meters = f.pos.h;
    pzs.RTK_height_meters = f.pos.h;
    if (f.cov_pos_N) pzs.PSigma = static_cast<float>(std::sqrt(f.cov_pos_N->trace()));
    pzs.Fix = 1;
    const Eigen::Matrix3d C_NtoE = earth::C_EtoN(f.pos.lat, f.pos.lon).transpose();
    const Eigen::Vector3d r_E = earth::geodeticToEcef(f.pos);
    const Eigen::Vector3d v_E = f.v_N ? Eigen::Vector3d(C_NtoE * *f.v_N) : Eigen::Vector3d::Constant(NAN);
    pzs.hasCartesianPosVel = true;
    pzs.cartesian_x = r_E[0];
    pzs.cartesian_y = r_E[1];
    pzs.cartesian_z = r_E[2];
    pzs.cartesian_vx = v_E[0];
    pzs.cartesian_vy = v_E[1];
    pzs.cartesian_vz = v_E[2];
    pzs.hasPosCov = f.cov_pos_N.has_value();
    if (f.cov_pos_N) pzs.pos_covariance = mrpt::math::CMatrixFloat44(cov4(C_NtoE * *f.cov_pos_N * C_NtoE.transpose()));
    pzs.hasVelCov = f.cov_vel_N.has_value();
    if (f.cov_vel_N) pzs.vel_covariance = mrpt::math::CMatrixFloat44(cov4(C_NtoE * *f.cov_vel_N * C_NtoE.transpose()));
    gps.setMsg(pzs);
    arch << gps;
  }
}

void writeRawlog(const std::string& path, const Recording& d, const RawlogWriteOptions& opt) {
  RawlogWriter w(path, d, opt);
  w.append(d, std::numeric_limits<double>::infinity());
  w.close();
}

}  // namespace navimpact::rawlog
