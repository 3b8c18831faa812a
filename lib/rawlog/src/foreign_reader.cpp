// Reading rawlogs that navimpact did not write: IMU and GNSS as MRPT's drivers
// record them (see writer.hpp, readRawlog with RawlogReadOptions).
#include <mrpt/obs/CObservationGPS.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <map>

#include "foreign_reader.hpp"
#include "frames.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/recording.hpp"
#include "navimpact/core/format.hpp"

namespace navimpact::rawlog::detail {

namespace {

namespace gnss = mrpt::obs::gnss;
constexpr double kDeg = M_PI / 180.0;
constexpr double kKnot = 1852.0 / 3600.0;

Eigen::Matrix3d rotationOf(const mrpt::poses::CPose3D& p) {
  Eigen::Matrix3d R;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) R(a, b) = p.getRotationMatrix()(a, b);
  return R;
}

struct Stamped {
  mrpt::Clock::time_point t;
  std::size_t entry;
};

struct ImuStream {
  std::vector<Stamped> when;
  std::vector<ImuRecord> rec;  // t filled at the end
};
struct GnssStream {
  std::vector<Stamped> when;
  std::vector<GnssFix> fix;
  std::optional<Eigen::Vector3d> lever_arm_B;
  bool rmcVelocity = false;
};

std::string list(const std::map<std::string, std::size_t>& m) {
  std::string s;
  for (const auto& [k, n] : m) s += (s.empty() ? "" : ", ") + printable(k, 40) + " (" + std::to_string(n) + ")";
  return s;
}

}  // namespace

Recording readForeignRawlog(EntryReader& reader, const RawlogReadOptions& opt) {
  const std::string path = reader.path();
  Recording d;
  d.source = path;
  std::map<std::string, ImuStream> imu;
  std::map<std::string, GnssStream> gps;
  std::map<std::string, std::size_t> imuCount, gpsCount;
  std::size_t entry = 0, skipped = 0;
  auto where = [&](std::size_t e, const std::string& label) {
    return path + ": entry " + std::to_string(e) + " (label " + printable(label, 40) + ")";
  };
  auto take = [&](const mrpt::obs::CObservation::Ptr& o, std::size_t e) {
    const std::string& label = o->sensorLabel;
    if (auto m = std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(o)) {
      // an IMU entry has rates and specific forces; others (e.g. altitude only) are skipped
      const bool has = m->has(mrpt::obs::IMU_WX) && m->has(mrpt::obs::IMU_WY) && m->has(mrpt::obs::IMU_WZ) &&
                       m->has(mrpt::obs::IMU_X_ACC) && m->has(mrpt::obs::IMU_Y_ACC) && m->has(mrpt::obs::IMU_Z_ACC);
      if (!has) { ++skipped; return; }
      ++imuCount[label];
      if (!opt.imu_label.empty() && label != opt.imu_label) return;
      // sensor axes as recorded; the mounting (sensorPose) in MRPT's vehicle frame x forward, y left, z up
      const Eigen::Matrix3d C = T_FLUtoFRD() * rotationOf(m->sensorPose);
      ImuRecord r;
      r.w_IB_B = C * Eigen::Vector3d(m->get(mrpt::obs::IMU_WX), m->get(mrpt::obs::IMU_WY), m->get(mrpt::obs::IMU_WZ));
      r.f_B = C * Eigen::Vector3d(m->get(mrpt::obs::IMU_X_ACC), m->get(mrpt::obs::IMU_Y_ACC), m->get(mrpt::obs::IMU_Z_ACC));
      if (!r.w_IB_B.allFinite() || !r.f_B.allFinite()) throw Error(where(e, label) + ": IMU value is not finite");
      // the physical ranges every reader applies (core/recording.hpp), on the entry that holds the record
      if (const std::string p = recordProblem(r); !p.empty()) throw Error(where(e, label) + ": " + p);
      auto& s = imu[label];
      s.when.push_back({m->timestamp, e});
      s.rec.push_back(r);
      return;
    }
    if (auto g = std::dynamic_pointer_cast<mrpt::obs::CObservationGPS>(o)) {
      GnssFix f;
      bool pos = false;
      if (const auto* p = g->getMsgByClassPtr<gnss::Message_TOPCON_PZS>(); p && storedTrue(p->hasCartesianPosVel)) {
        f.pos = earth::ecefToGeodetic(Eigen::Vector3d(p->cartesian_x, p->cartesian_y, p->cartesian_z));
        const Eigen::Matrix3d C_EtoN = earth::C_EtoN(f.pos.lat, f.pos.lon);
        const Eigen::Vector3d v_E(p->cartesian_vx, p->cartesian_vy, p->cartesian_vz);
        if (v_E.allFinite()) f.v_N.emplace() = C_EtoN * v_E;
        if (storedTrue(p->hasPosCov)) f.cov_pos_N.emplace() = C_EtoN * p->pos_covariance.asEigen().topLeftCorner<3, 3>().cast<double>() * C_EtoN.transpose();
        if (storedTrue(p->hasVelCov) && f.v_N) f.cov_vel_N.emplace() = C_EtoN * p->vel_covariance.asEigen().topLeftCorner<3, 3>().cast<double>() * C_EtoN.transpose();
        pos = true;
      } else if (const auto* p = g->getMsgByClassPtr<gnss::Message_TOPCON_PZS>(); p && p->Fix > 0) {
        f.pos = {p->latitude_degrees * kDeg, p->longitude_degrees * kDeg, p->height_meters};
        pos = true;
      } else if (const auto* b = g->getMsgByClassPtr<gnss::Message_NV_OEM6_BESTPOS>()) {
        // height above mean sea level + undulation = ellipsoidal
        f.pos = {b->fields.lat * kDeg, b->fields.lon * kDeg, b->fields.hgt + b->fields.undulation};
        if (b->fields.lat_sigma > 0 && b->fields.lon_sigma > 0 && b->fields.hgt_sigma > 0)
          f.cov_pos_N = Eigen::Vector3d(b->fields.lat_sigma, b->fields.lon_sigma, b->fields.hgt_sigma).cwiseAbs2().asDiagonal();
        pos = b->fields.solution_stat == gnss::nv_oem6_solution_status::SOL_COMPUTED;
      } else if (const auto* a = g->getMsgByClassPtr<gnss::Message_NMEA_GGA>()) {
        // NMEA: altitude above mean sea level + geoidal separation = ellipsoidal
        f.pos = {a->fields.latitude_degrees * kDeg, a->fields.longitude_degrees * kDeg,
                 a->fields.altitude_meters + a->fields.geoidal_distance};
        pos = a->fields.fix_quality > 0;
      }
      if (!pos) { ++skipped; return; }
      ++gpsCount[label];
      if (!opt.gnss_label.empty() && label != opt.gnss_label) return;
      auto& s = gps[label];
      if (!f.v_N) {  // horizontal velocity from RMC or VTG: the vertical is unknown
        double speed = NAN, course = NAN;
        if (const auto* r = g->getMsgByClassPtr<gnss::Message_NMEA_RMC>(); r && r->fields.validity_char == 'A') {
          speed = r->fields.speed_knots * kKnot;
          course = r->fields.direction_degrees * kDeg;
        } else if (const auto* v = g->getMsgByClassPtr<gnss::Message_NMEA_VTG>()) {
          speed = v->fields.ground_speed_kmh / 3.6;
          course = v->fields.true_track * kDeg;
        }
        if (std::isfinite(speed) && std::isfinite(course)) {
          f.v_N = Eigen::Vector3d(speed * std::cos(course), speed * std::sin(course), 0.0);
          f.cov_vel_N = Eigen::Vector3d(kRmcSigmaH, kRmcSigmaH, kRmcSigmaV).cwiseAbs2().asDiagonal();
          s.rmcVelocity = true;
        }
      }
      if (!s.lever_arm_B && (g->sensorPose.x() != 0 || g->sensorPose.y() != 0 || g->sensorPose.z() != 0))
        s.lever_arm_B = T_FLUtoFRD() * Eigen::Vector3d(g->sensorPose.x(), g->sensorPose.y(), g->sensorPose.z());
      if (const std::string p = recordProblem(f); !p.empty()) throw Error(where(e, label) + ": " + p);
      s.when.push_back({g->timestamp, e});
      s.fix.push_back(f);
      return;
    }
    ++skipped;
  };

  for (;;) {
    const mrpt::serialization::CSerializable::Ptr obj = reader.next();
    if (!obj) break;
    entry = reader.entry();
    if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(obj)) {
      for (const auto& o : *sf) take(o, entry);
    } else if (auto o = std::dynamic_pointer_cast<mrpt::obs::CObservation>(obj)) {
      take(o, entry);
    } else {
      ++skipped;
    }
  }

  auto choose = [&](const std::map<std::string, std::size_t>& count, const std::string& wanted, const char* what,
                    const char* flag) -> std::string {
    if (!wanted.empty()) {
      if (!count.count(wanted))
        throw Error(path + ": no " + what + " entries with label '" + printable(wanted, 40) + "' (labels found: " +
                    (count.empty() ? std::string("none") : list(count)) + ")");
      return wanted;
    }
    if (count.size() > 1)
      throw Error(path + ": several " + what + " labels: " + list(count) + "; choose one with " + flag);
    return count.empty() ? std::string() : count.begin()->first;
  };
  const std::string il = choose(imuCount, opt.imu_label, "IMU", "--imu-label");
  const std::string gl = choose(gpsCount, opt.gnss_label, "GNSS", "--gnss-label");
  if (il.empty()) throw Error(path + ": no IMU entries (CObservationIMU with angular rates and accelerations)");

  // time zero: the first chosen entry; times checked non-decreasing per stream
  auto& is = imu[il];
  mrpt::Clock::time_point base = is.when.front().t;
  if (!gl.empty() && gps[gl].when.front().t < base) base = gps[gl].when.front().t;
  const double u = mrpt::Clock::toDouble(base);
  d.start_unix_s = static_cast<long long>(std::floor(u));
  d.t_start_s = static_cast<double>(d.start_unix_s) - u;
  auto rel = [&](const mrpt::Clock::time_point& t) { return static_cast<double>((t - base).count()) * kTick; };
  for (std::size_t i = 0; i < is.rec.size(); ++i) {
    is.rec[i].t = rel(is.when[i].t);
    if (i > 0 && is.rec[i].t < is.rec[i - 1].t)
      throw Error(where(is.when[i].entry, il) + ": IMU timestamp goes backwards");
  }
  d.imu = std::move(is.rec);
  if (!gl.empty()) {
    auto& gs = gps[gl];
    for (std::size_t i = 0; i < gs.fix.size(); ++i) {
      gs.fix[i].t = rel(gs.when[i].t);
      if (i > 0 && gs.fix[i].t < gs.fix[i - 1].t)
        throw Error(where(gs.when[i].entry, gl) + ": GNSS timestamp goes backwards");
    }
    d.gnss = std::move(gs.fix);
    d.lever_arm_B = gs.lever_arm_B;
    if (!d.gnss.empty()) d.origin = d.gnss.front().pos;
    if (gs.rmcVelocity)
      d.notices.push_back("GNSS velocity from NMEA RMC/VTG: horizontal only (sigma " + formatNumber(kRmcSigmaH) +
                          " m/s assumed), vertical unknown (sigma " + formatNumber(kRmcSigmaV) + " m/s)");
  }
  d.notices.push_back("rawlog not written by navimpact: IMU label '" + il + "' (sensor axes turned by its sensorPose into "
                      "the vehicle frame), GNSS label '" + (gl.empty() ? std::string("none") : gl) + "'");
  if (skipped) d.notices.push_back(std::to_string(skipped) + " entries with other labels or types skipped");
  if (d.imu.size() >= 2) d.imu_rate_hz = (d.imu.size() - 1) / (d.imu.back().t - d.imu.front().t);
  return d;
}

}  // namespace navimpact::rawlog::detail
