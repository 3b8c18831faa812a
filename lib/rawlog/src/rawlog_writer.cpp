// Rawlog writer and reader of navimpact::Recording (see writer.hpp).
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
#include <map>
#include <stdexcept>
#include <vector>

#include "entry_reader.hpp"
#include "foreign_reader.hpp"
#include "gz_member_sink.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/imu_series.hpp"

namespace navimpact::rawlog {

using mrpt::obs::CObservationIMU;
namespace gnss = mrpt::obs::gnss;

namespace {

constexpr double kTick = 1e-7;  // MRPT Clock resolution [s]

mrpt::Clock::time_point stamp(long long startUnix, double tRel) {
  const auto base = mrpt::Clock::fromDouble(static_cast<double>(startUnix));
  return base + mrpt::Clock::duration(std::llround(tRel / kTick));
}

struct Entry {
  double t;
  int order;  // tie-break: GT 0, IMU 1, BARO 2, GNSS 3
  std::size_t index;
};

// The reference as a pose observation in MRPT's conventions: map frame ENU at
// the origin (x east, y north, z up), vehicle frame x forward, y left, z up.
// T_NtoENU maps NED to ENU; T_FLUtoFRD maps FLU to FRD (both are their own inverse).
const Eigen::Matrix3d& T_NtoENU() {
  static const Eigen::Matrix3d T = (Eigen::Matrix3d() << 0, 1, 0, 1, 0, 0, 0, 0, -1).finished();
  return T;
}
const Eigen::Matrix3d& T_FLUtoFRD() {
  static const Eigen::Matrix3d T = Eigen::Vector3d(1, -1, -1).asDiagonal();
  return T;
}
// Attitude variance that stands for "no attitude known" (sigma 1e6 rad).
constexpr double kUnknownAttitudeVar = 1e12;

Eigen::Matrix4f cov4(const Eigen::Matrix3d& c) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Zero();
  m.topLeftCorner<3, 3>() = c.cast<float>();
  return m;
}

}  // namespace

void writeRawlog(const std::string& path, const Recording& d, const RawlogWriteOptions& opt) {
  // gzip members compressed on worker threads (see gz_member_sink.hpp)
  detail::GzMemberSink out(path, opt.gzip ? std::clamp(opt.gzip_level, 1, 9) : 0);
  auto arch = mrpt::serialization::archiveFrom(out);
  const long long su = d.start_unix_s;
  auto rel = [&](double t) { return t - d.t_start_s; };

  {
    mrpt::obs::CObservationComment c;
    c.sensorLabel = "SCENARIO";
    c.timestamp = stamp(su, 0.0);
    c.text = d.metadata;
    arch << c;
  }
  std::vector<Entry> order;
  order.reserve(d.imu.size() + d.gnss.size() + d.baro.size() + d.reference.size());
  for (std::size_t i = 0; i < d.reference.size(); ++i) order.push_back({d.reference[i].t, 0, i});
  for (std::size_t i = 0; i < d.imu.size(); ++i) order.push_back({d.imu[i].t, 1, i});
  for (std::size_t i = 0; i < d.baro.size(); ++i) order.push_back({d.baro[i].t, 2, i});
  for (std::size_t i = 0; i < d.gnss.size(); ++i) order.push_back({d.gnss[i].t, 3, i});
  std::stable_sort(order.begin(), order.end(), [](const Entry& a, const Entry& b) {
    const auto ta = std::llround(a.t / kTick), tb = std::llround(b.t / kTick);
    return ta != tb ? ta < tb : a.order < b.order;
  });

  CObservationIMU imu, baro, gtVel;
  imu.sensorLabel = "IMU";
  {  // the values are body FRD: the IMU's mounting in MRPT's vehicle frame (x forward, y left, z up)
    // is a half turn about x, written exactly (readers that apply sensorPose get FLU values)
    mrpt::math::CMatrixDouble33 rot;
    rot.setZero();
    rot(0, 0) = 1.0;
    rot(1, 1) = -1.0;
    rot(2, 2) = -1.0;
    mrpt::math::CVectorFixedDouble<3> zero;
    zero[0] = zero[1] = zero[2] = 0.0;
    imu.sensorPose = mrpt::poses::CPose3D(rot, zero);
  }
  baro.sensorLabel = "BARO";
  gtVel.sensorLabel = "GT_VEL";
  mrpt::obs::CObservationRobotPose gt;
  gt.sensorLabel = "GT";
  mrpt::obs::CObservationGPS gps;
  gps.sensorLabel = "GNSS";
  gps.has_satellite_timestamp = false;
  if (d.lever_arm_B) {  // antenna on the vehicle, MRPT vehicle frame FLU
    const Eigen::Vector3d l = T_FLUtoFRD() * *d.lever_arm_B;
    gps.sensorPose = mrpt::poses::CPose3D(l[0], l[1], l[2], 0, 0, 0);
  }
  for (const Entry& e : order) {
    const auto ts = stamp(su, rel(e.t));
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
      const double tu = static_cast<double>(su) + rel(e.t);
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
  out.close();
  if (!std::filesystem::exists(path)) throw Error(path + ": rawlog was not written");
}

Recording readRawlog(const std::string& path, const RawlogReadOptions& opt) {
  InputScope scope(path);
  if (!std::filesystem::exists(path)) throw Error(path + ": rawlog not found");
  {
    // navimpact's own rawlogs start with their comment; anything else is read
    // as MRPT's drivers record (labels, sensor axes and sensorPose)
    detail::EntryReader peek(path);
    const auto first = peek.next();
    const auto c = std::dynamic_pointer_cast<mrpt::obs::CObservationComment>(first);
    if (first && !(c && (c->text.empty() || c->text.find("navimpact_scenario") != std::string::npos))) {
      detail::EntryReader reader(path);
      return detail::readForeignRawlog(reader, opt);
    }
  }
  // Entries through one 1 MiB buffer (MRPT's archive reads every field with its
  // own small Read() call), with the length caps and gzip checks of EntryReader.
  detail::EntryReader reader(path);
  Recording d;
  d.source = path;
  bool haveComment = false, haveOrigin = false, haveBase = false;
  mrpt::Clock::time_point base{};
  std::size_t entry = 0, skipped = 0;
  double lastT = -1e300;
  std::string lastLabel;
  std::map<std::string, std::pair<double, std::size_t>> lastOfLabel;  // label -> time, entry of its last record
  earth::Geodetic origin;
  auto where = [&](const std::string& label, double t) {
    std::string s = path + ": entry " + std::to_string(entry);
    if (!label.empty()) s += " (label " + printable(label, 40) + (std::isfinite(t) ? ", t = " + std::to_string(t) + " s" : "") + ")";
    return s;
  };
  for (;;) {
    const mrpt::serialization::CSerializable::Ptr obj = reader.next();
    if (!obj) break;  // clean end between entries
    entry = reader.entry();
    if (auto c = std::dynamic_pointer_cast<mrpt::obs::CObservationComment>(obj)) {
      if (!haveComment) {
        haveComment = true;
        d.metadata = c->text;
        try {
          const YAML::Node y = YAML::Load(c->text)["navimpact_scenario"];
          if (y && y["origin"]) {
            origin = {y["origin"]["lat_deg"].as<double>() * M_PI / 180, y["origin"]["lon_deg"].as<double>() * M_PI / 180,
                      y["origin"]["height_m"].as<double>()};
            haveOrigin = true;
          }
          if (y && y["time"] && y["time"]["start_unix_s"]) {
            d.start_unix_s = y["time"]["start_unix_s"].as<long long>();
            base = mrpt::Clock::fromDouble(static_cast<double>(d.start_unix_s));
            haveBase = true;
          }
          if (y && y["imu"] && y["imu"]["rate_hz"]) d.imu_rate_hz = y["imu"]["rate_hz"].as<double>();
          if (y && y["gnss"] && y["gnss"]["lever_arm_B_m"]) {
            const YAML::Node l = y["gnss"]["lever_arm_B_m"];
            d.lever_arm_B = Eigen::Vector3d(l[0].as<double>(), l[1].as<double>(), l[2].as<double>());
          }
        } catch (const YAML::Exception& e) {
          throw Error(where("SCENARIO", NAN) + ": scenario comment is not valid YAML (" + e.msg + ")");
        }
      }
      continue;
    }
    auto o = std::dynamic_pointer_cast<mrpt::obs::CObservation>(obj);
    if (!o) { ++skipped; continue; }
    const std::string& label = o->sensorLabel;
    if (!haveBase && (label == "IMU" || label == "GT" || label == "GT_VEL" || label == "GNSS" || label == "BARO")) {
      // no time base in the comment: the first entry of a known label defines
      // time zero; its absolute time is kept as start_unix_s + (0 - t_start_s)
      base = o->timestamp;
      haveBase = true;
      const double u = mrpt::Clock::toDouble(base);
      d.start_unix_s = static_cast<long long>(std::floor(u));
      d.t_start_s = static_cast<double>(d.start_unix_s) - u;
    }
    const double t = haveBase ? static_cast<double>((o->timestamp - base).count()) * kTick : 0.0;
    if (t < lastT)
      throw Error(where(label, t) + ": timestamp goes backwards (previous entry, label " + printable(lastLabel, 40) + ", at t = " +
                  std::to_string(lastT) + " s)");
    lastT = t;
    lastLabel = label;
    if (label == "IMU" || label == "BARO" || label == "GT" || label == "GNSS") {
      // Each sensor's own timestamps increase strictly: a second record at the
      // same time is a duplicate (a GNSS fix applied twice), never accepted.
      auto [it, first] = lastOfLabel.try_emplace(label, t, entry);
      if (!first && !(t > it->second.first))
        throw Error(where(label, t) + ": same time as " + printable(label, 40) + " entry " +
                    std::to_string(it->second.second) + " (a duplicated record; each sensor's timestamps must increase)");
      it->second = {t, entry};
    }
    if (label == "GT" && std::dynamic_pointer_cast<mrpt::obs::CObservationRobotPose>(o)) {
      const auto& rp = *std::dynamic_pointer_cast<mrpt::obs::CObservationRobotPose>(o);
      if (!haveOrigin) throw Error(where(label, t) + ": the reference needs the scenario comment's origin, none found before it");
      ReferenceRecord r;
      r.t = t;
      const auto& m = rp.pose.mean;
      r.p_L = T_NtoENU() * Eigen::Vector3d(m.x(), m.y(), m.z());
      const auto& c = rp.pose.cov;
      if (!(c(3, 3) >= kUnknownAttitudeVar / 2)) {
        Eigen::Matrix3d R;
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) R(a, b) = m.getRotationMatrix()(a, b);
        r.q_BtoN.emplace(Eigen::Quaterniond(T_NtoENU() * R * T_FLUtoFRD()).normalized());
        if (c(3, 3) > 0 && c(4, 4) > 0 && c(5, 5) > 0)
          r.sigma_att = Eigen::Vector3d(std::sqrt(c(5, 5)), std::sqrt(c(4, 4)), std::sqrt(c(3, 3)));
      }
      if (c(0, 0) > 0 && c(1, 1) > 0 && c(2, 2) > 0)
        r.sigma_p_L = Eigen::Vector3d(std::sqrt(c(1, 1)), std::sqrt(c(0, 0)), std::sqrt(c(2, 2)));
      d.reference.push_back(r);
      continue;
    }
    if (label == "GT_VEL") {
      auto m = std::dynamic_pointer_cast<CObservationIMU>(o);
      if (!m) throw Error(where(label, t) + ": expected a CObservationIMU, found " + o->GetRuntimeClass()->className);
      if (d.reference.empty() || d.reference.back().t != t || d.reference.back().v_N)
        throw Error(where(label, t) + ": reference velocity without a reference pose (label GT) at the same time before it");
      for (auto i : {mrpt::obs::IMU_X_VEL, mrpt::obs::IMU_Y_VEL, mrpt::obs::IMU_Z_VEL})
        if (!m->has(i)) throw Error(where(label, t) + ": a velocity field (IMU_X_VEL, IMU_Y_VEL, IMU_Z_VEL) is not set");
      d.reference.back().v_N = Eigen::Vector3d(m->get(mrpt::obs::IMU_X_VEL), m->get(mrpt::obs::IMU_Y_VEL),
                                               m->get(mrpt::obs::IMU_Z_VEL));
      continue;
    }
    if (label == "IMU" || label == "BARO" || label == "GT") {
      auto m = std::dynamic_pointer_cast<CObservationIMU>(o);
      if (!m) throw Error(where(label, t) + ": expected a CObservationIMU, found " + o->GetRuntimeClass()->className);
      auto need = [&](mrpt::obs::TIMUDataIndex i, const char* name) {
        if (!m->has(i)) throw Error(where(label, t) + ": field " + name + " is not set");
        const double v = m->get(i);
        if (!std::isfinite(v)) throw Error(where(label, t) + ": field " + name + " is not finite");
        return v;
      };
      auto rate = [&](mrpt::obs::TIMUDataIndex i, const char* name, double lim, const char* limText) {
        const double v = need(i, name);
        if (std::abs(v) > lim)
          throw Error(where(label, t) + ": " + name + " = " + formatNumber(v) + " is beyond any IMU (|value| <= " +
                      limText + ")");
        return v;
      };
      if (label == "IMU") {
        ImuRecord r;
        r.t = t;
        const char* w = "1000 rad/s";
        const char* f = "1e5 m/s^2";
        r.w_IB_B = {rate(mrpt::obs::IMU_WX, "IMU_WX", kMaxAbsAngularRate, w),
                    rate(mrpt::obs::IMU_WY, "IMU_WY", kMaxAbsAngularRate, w),
                    rate(mrpt::obs::IMU_WZ, "IMU_WZ", kMaxAbsAngularRate, w)};
        r.f_B = {rate(mrpt::obs::IMU_X_ACC, "IMU_X_ACC", kMaxAbsSpecificForce, f),
                 rate(mrpt::obs::IMU_Y_ACC, "IMU_Y_ACC", kMaxAbsSpecificForce, f),
                 rate(mrpt::obs::IMU_Z_ACC, "IMU_Z_ACC", kMaxAbsSpecificForce, f)};
        d.imu.push_back(r);
      } else if (label == "BARO") {
        d.baro.push_back({t, need(mrpt::obs::IMU_ALTITUDE, "IMU_ALTITUDE"), std::nullopt});
      } else {
        if (!haveOrigin) throw Error(where(label, t) + ": ground truth needs the scenario comment's origin, none found before it");
        ReferenceRecord r;
        r.t = t;
        r.p_L = {need(mrpt::obs::IMU_X, "IMU_X"), need(mrpt::obs::IMU_Y, "IMU_Y"), need(mrpt::obs::IMU_Z, "IMU_Z")};
        // velocity and attitude: all of their fields or none
        if (m->has(mrpt::obs::IMU_X_VEL) || m->has(mrpt::obs::IMU_Y_VEL) || m->has(mrpt::obs::IMU_Z_VEL))
          r.v_N = Eigen::Vector3d(need(mrpt::obs::IMU_X_VEL, "IMU_X_VEL"), need(mrpt::obs::IMU_Y_VEL, "IMU_Y_VEL"),
                                  need(mrpt::obs::IMU_Z_VEL, "IMU_Z_VEL"));
        if (m->has(mrpt::obs::IMU_ORI_QUAT_W) || m->has(mrpt::obs::IMU_ORI_QUAT_X) ||
            m->has(mrpt::obs::IMU_ORI_QUAT_Y) || m->has(mrpt::obs::IMU_ORI_QUAT_Z))
          r.q_BtoN = Eigen::Quaterniond(need(mrpt::obs::IMU_ORI_QUAT_W, "IMU_ORI_QUAT_W"),
                                        need(mrpt::obs::IMU_ORI_QUAT_X, "IMU_ORI_QUAT_X"),
                                        need(mrpt::obs::IMU_ORI_QUAT_Y, "IMU_ORI_QUAT_Y"),
                                        need(mrpt::obs::IMU_ORI_QUAT_Z, "IMU_ORI_QUAT_Z"));
        d.reference.push_back(r);
      }
    } else if (label == "GNSS") {
      auto g = std::dynamic_pointer_cast<mrpt::obs::CObservationGPS>(o);
      if (!g) throw Error(where(label, t) + ": expected a CObservationGPS, found " + o->GetRuntimeClass()->className);
      GnssFix f;
      f.t = t;
      if (!d.lever_arm_B && (g->sensorPose.x() != 0 || g->sensorPose.y() != 0 || g->sensorPose.z() != 0))
        d.lever_arm_B = T_FLUtoFRD() * Eigen::Vector3d(g->sensorPose.x(), g->sensorPose.y(), g->sensorPose.z());
      if (const auto* p = g->getMsgByClassPtr<gnss::Message_TOPCON_PZS>(); p && p->hasCartesianPosVel) {
        const Eigen::Vector3d r_E(p->cartesian_x, p->cartesian_y, p->cartesian_z);
        f.pos = earth::ecefToGeodetic(r_E);
        const Eigen::Matrix3d C_EtoN = earth::C_EtoN(f.pos.lat, f.pos.lon);
        const Eigen::Vector3d v_E(p->cartesian_vx, p->cartesian_vy, p->cartesian_vz);
        // products assigned into the emplaced values (as into a plain Matrix3d: Eigen evaluates an
        // assignment and a construction from a product differently in the last bit)
        if (!(v_E.allFinite() || v_E.array().isNaN().all()))
          throw Error(where(label, t) + ": GNSS velocity is not finite");
        if (v_E.allFinite()) f.v_N.emplace() = C_EtoN * v_E;
        if (p->hasPosCov) {
          const Eigen::Matrix3d c = p->pos_covariance.asEigen().topLeftCorner<3, 3>().cast<double>();
          f.cov_pos_N.emplace() = C_EtoN * c * C_EtoN.transpose();
        }
        if (p->hasVelCov) {
          const Eigen::Matrix3d c = p->vel_covariance.asEigen().topLeftCorner<3, 3>().cast<double>();
          f.cov_vel_N.emplace() = C_EtoN * c * C_EtoN.transpose();
        }
      } else if (const auto* gga = g->getMsgByClassPtr<gnss::Message_NMEA_GGA>()) {
        f.pos = {gga->fields.latitude_degrees * M_PI / 180, gga->fields.longitude_degrees * M_PI / 180,
                 gga->fields.altitude_meters + gga->fields.geoidal_distance * 0.0};
      } else {
        throw Error(where(label, t) + ": GNSS entry has neither a TOPCON_PZS nor an NMEA GGA message");
      }
      if (!std::isfinite(f.pos.lat) || !std::isfinite(f.pos.lon) || !std::isfinite(f.pos.h) ||
          std::abs(f.pos.lat) > M_PI / 2 || std::abs(f.pos.lon) > 2 * M_PI || std::abs(f.pos.h) > 1e7)
        throw Error(where(label, t) + ": GNSS position is not a place on Earth (latitude, longitude, height)");
      d.gnss.push_back(f);
    } else {
      ++skipped;
    }
  }
  if (skipped) d.notices.push_back(std::to_string(skipped) + " entries with other labels or types skipped");
  d.origin = origin;
  if (!haveOrigin && !d.gnss.empty()) d.origin = d.gnss.front().pos;
  return d;
}

}  // namespace navimpact::rawlog
