// Rawlog reader: record by record (RawlogReader), or whole (readRawlog). See reader.hpp, writer.hpp.
#include "navimpact/rawlog/reader.hpp"

#include "navimpact/core/output.hpp"

#include <mrpt/obs/CObservationComment.h>
#include <mrpt/obs/CObservationGPS.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/poses/CPose3D.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <deque>
#include <tuple>
#include <filesystem>
#include <map>
#include <optional>

#include "entry_reader.hpp"
#include "foreign_reader.hpp"
#include "frames.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/imu_series.hpp"
#include "navimpact/core/yaml_load.hpp"

namespace navimpact::rawlog {

using mrpt::obs::CObservationIMU;
namespace gnss = mrpt::obs::gnss;
using detail::kTick;
using detail::kUnknownAttitudeVar;
using detail::storedTrue;
using detail::T_FLUtoFRD;
using detail::T_NtoENU;

struct RawlogReader::Impl {
  std::string path;
  Recording head;  // streams empty
  std::optional<detail::EntryReader> reader;

  // a rawlog navimpact wrote: entry by entry
  bool haveOrigin = false, haveBase = false, fromCommentOrigin = false;
  mrpt::Clock::time_point base{};
  std::size_t entry = 0, skipped = 0;
  double lastT = -1e300;
  std::string lastLabel;
  std::map<std::string, std::pair<double, std::size_t>> lastOfLabel;  // label -> time, entry of its last record
  earth::Geodetic origin;
  std::optional<RawlogRecord> pendingGt;  // a GT whose GT_VEL may still follow
  std::deque<RawlogRecord> ready;
  bool end = false;

  // a rawlog navimpact did not write: read whole, returned merged in time order
  std::optional<Recording> foreign;
  std::size_t fi = 0, fg = 0;

  std::string where(const std::string& label, double t) const {
    std::string s = path + ": entry " + std::to_string(entry);
    if (!label.empty())
      s += " (label " + printable(label, 40) + (std::isfinite(t) ? ", t = " + formatNumber(t, 10) + " s" : "") + ")";
    return s;
  }

  void readComment(const mrpt::obs::CObservationComment& c) {
    head.metadata = c.text;
    try {
      const YAML::Node y = loadYaml(c.text)["navimpact_scenario"];
      if (y && y["origin"]) {
        origin = {y["origin"]["lat_deg"].as<double>() * M_PI / 180, y["origin"]["lon_deg"].as<double>() * M_PI / 180,
                  y["origin"]["height_m"].as<double>()};
        haveOrigin = true;
        head.origin = origin;
      }
      if (y && y["time"] && y["time"]["start_unix_s"]) {
        head.start_unix_s = y["time"]["start_unix_s"].as<long long>();
        base = mrpt::Clock::fromDouble(static_cast<double>(head.start_unix_s));
        haveBase = true;
      }
      if (y && y["imu"] && y["imu"]["rate_hz"]) head.imu_rate_hz = y["imu"]["rate_hz"].as<double>();
      if (y && y["gnss"] && y["gnss"]["lever_arm_B_m"]) {
        const YAML::Node l = y["gnss"]["lever_arm_B_m"];
        head.lever_arm_B = Eigen::Vector3d(l[0].as<double>(), l[1].as<double>(), l[2].as<double>());
      }
    } catch (const YAML::Exception& e) {
      throw Error(where("SCENARIO", NAN) + ": scenario comment is not valid YAML (" + printable(e.msg) + ")");
    }
  }

  /// The physical ranges every reader applies (recording.hpp), checked on the entry that holds the record.
  void checkPlausible(const RawlogRecord& r, const std::string& label, double t) const {
    std::string p;
    switch (r.kind) {
      case RawlogRecord::Kind::Imu: p = recordProblem(r.imu); break;
      case RawlogRecord::Kind::Gnss: p = recordProblem(r.gnss); break;
      case RawlogRecord::Kind::Baro: p = recordProblem(r.baro); break;
      case RawlogRecord::Kind::Reference: p = recordProblem(r.reference); break;
    }
    if (!p.empty()) throw Error(where(label, t) + ": " + p);
  }

  void emit(RawlogRecord&& r) { ready.push_back(std::move(r)); }
  void flushGt() {
    if (pendingGt) {
      emit(std::move(*pendingGt));
      pendingGt.reset();
    }
  }

  // Read entries until a record is ready or the file ends.
  void readMore() {
    while (ready.empty() && !end) {
      const mrpt::serialization::CSerializable::Ptr obj = reader->next();
      if (!obj) {  // clean end between entries
        end = true;
        flushGt();
        if (skipped) head.notices.push_back(std::to_string(skipped) + " entries with other labels or types skipped");
        return;
      }
      entry = reader->entry();
      if (std::dynamic_pointer_cast<mrpt::obs::CObservationComment>(obj)) continue;  // the first one was read
      auto o = std::dynamic_pointer_cast<mrpt::obs::CObservation>(obj);
      if (!o) {
        ++skipped;
        continue;
      }
      take(*o);
    }
  }

  void take(mrpt::obs::CObservation& ob) {
    const std::string& label = ob.sensorLabel;
    if (!haveBase && (label == "IMU" || label == "GT" || label == "GT_VEL" || label == "GNSS" || label == "BARO")) {
      // no time base in the comment: the first entry of a known label defines
      // time zero; its absolute time is kept as start_unix_s + (0 - t_start_s)
      base = ob.timestamp;
      haveBase = true;
      const double u = mrpt::Clock::toDouble(base);
      head.start_unix_s = static_cast<long long>(std::floor(u));
      head.t_start_s = static_cast<double>(head.start_unix_s) - u;
    }
    const double t = haveBase ? static_cast<double>((ob.timestamp - base).count()) * kTick : 0.0;
    if (t < lastT)
      throw Error(where(label, t) + ": timestamp goes backwards (previous entry, label " + printable(lastLabel, 40) +
                  ", at t = " + formatNumber(lastT, 10) + " s)");
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
    // a pending GT is complete once time moves on or another GT comes
    if (pendingGt && (t > pendingGt->t || label == "GT")) flushGt();
    if (label == "GT" && dynamic_cast<const mrpt::obs::CObservationRobotPose*>(&ob)) {
      const auto& rp = dynamic_cast<const mrpt::obs::CObservationRobotPose&>(ob);
      if (!haveOrigin) throw Error(where(label, t) + ": the reference needs the scenario comment's origin, none found before it");
      RawlogRecord rec;
      rec.kind = RawlogRecord::Kind::Reference;
      rec.t = t;
      ReferenceRecord& r = rec.reference;
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
      checkPlausible(rec, label, t);
      pendingGt = std::move(rec);
      return;
    }
    if (label == "GT_VEL") {
      auto m = dynamic_cast<const CObservationIMU*>(&ob);
      if (!m) throw Error(where(label, t) + ": expected a CObservationIMU, found " + ob.GetRuntimeClass()->className);
      if (!pendingGt || pendingGt->t != t || pendingGt->reference.v_N)
        throw Error(where(label, t) + ": reference velocity without a reference pose (label GT) at the same time before it");
      for (auto i : {mrpt::obs::IMU_X_VEL, mrpt::obs::IMU_Y_VEL, mrpt::obs::IMU_Z_VEL})
        if (!m->has(i)) throw Error(where(label, t) + ": a velocity field (IMU_X_VEL, IMU_Y_VEL, IMU_Z_VEL) is not set");
      pendingGt->reference.v_N = Eigen::Vector3d(m->get(mrpt::obs::IMU_X_VEL), m->get(mrpt::obs::IMU_Y_VEL),
                                                 m->get(mrpt::obs::IMU_Z_VEL));
      checkPlausible(*pendingGt, label, t);
      return;
    }
    if (label == "IMU" || label == "BARO" || label == "GT") {
      auto m = dynamic_cast<const CObservationIMU*>(&ob);
      if (!m) throw Error(where(label, t) + ": expected a CObservationIMU, found " + ob.GetRuntimeClass()->className);
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
      RawlogRecord rec;
      rec.t = t;
      if (label == "IMU") {
        rec.kind = RawlogRecord::Kind::Imu;
        ImuRecord& r = rec.imu;
        r.t = t;
        const char* w = "1000 rad/s";
        const char* f = "1e5 m/s^2";
        r.w_IB_B = {rate(mrpt::obs::IMU_WX, "IMU_WX", kMaxAbsAngularRate, w),
                    rate(mrpt::obs::IMU_WY, "IMU_WY", kMaxAbsAngularRate, w),
                    rate(mrpt::obs::IMU_WZ, "IMU_WZ", kMaxAbsAngularRate, w)};
        r.f_B = {rate(mrpt::obs::IMU_X_ACC, "IMU_X_ACC", kMaxAbsSpecificForce, f),
                 rate(mrpt::obs::IMU_Y_ACC, "IMU_Y_ACC", kMaxAbsSpecificForce, f),
                 rate(mrpt::obs::IMU_Z_ACC, "IMU_Z_ACC", kMaxAbsSpecificForce, f)};
        emit(std::move(rec));
      } else if (label == "BARO") {
        rec.kind = RawlogRecord::Kind::Baro;
        rec.baro = {t, need(mrpt::obs::IMU_ALTITUDE, "IMU_ALTITUDE"), std::nullopt};
        checkPlausible(rec, label, t);
        emit(std::move(rec));
      } else {
        if (!haveOrigin) throw Error(where(label, t) + ": ground truth needs the scenario comment's origin, none found before it");
        rec.kind = RawlogRecord::Kind::Reference;
        ReferenceRecord& r = rec.reference;
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
        checkPlausible(rec, label, t);
        pendingGt = std::move(rec);
      }
    } else if (label == "GNSS") {
      auto g = dynamic_cast<mrpt::obs::CObservationGPS*>(&ob);
      if (!g) throw Error(where(label, t) + ": expected a CObservationGPS, found " + ob.GetRuntimeClass()->className);
      RawlogRecord rec;
      rec.kind = RawlogRecord::Kind::Gnss;
      rec.t = t;
      GnssFix& f = rec.gnss;
      f.t = t;
      if (!head.lever_arm_B && (g->sensorPose.x() != 0 || g->sensorPose.y() != 0 || g->sensorPose.z() != 0))
        head.lever_arm_B = T_FLUtoFRD() * Eigen::Vector3d(g->sensorPose.x(), g->sensorPose.y(), g->sensorPose.z());
      if (const auto* p = g->getMsgByClassPtr<gnss::Message_TOPCON_PZS>(); p && storedTrue(p->hasCartesianPosVel)) {
        const Eigen::Vector3d r_E(p->cartesian_x, p->cartesian_y, p->cartesian_z);
        f.pos = earth::ecefToGeodetic(r_E);
        const Eigen::Matrix3d C_EtoN = earth::C_EtoN(f.pos.lat, f.pos.lon);
        const Eigen::Vector3d v_E(p->cartesian_vx, p->cartesian_vy, p->cartesian_vz);
        // products assigned into the emplaced values (as into a plain Matrix3d: Eigen evaluates an
        // assignment and a construction from a product differently in the last bit)
        if (!(v_E.allFinite() || v_E.array().isNaN().all()))
          throw Error(where(label, t) + ": GNSS velocity is not finite");
        if (v_E.allFinite()) f.v_N.emplace() = C_EtoN * v_E;
        if (storedTrue(p->hasPosCov)) {
          const Eigen::Matrix3d c = p->pos_covariance.asEigen().topLeftCorner<3, 3>().cast<double>();
          f.cov_pos_N.emplace() = C_EtoN * c * C_EtoN.transpose();
        }
        if (storedTrue(p->hasVelCov)) {
          const Eigen::Matrix3d c = p->vel_covariance.asEigen().topLeftCorner<3, 3>().cast<double>();
          f.cov_vel_N.emplace() = C_EtoN * c * C_EtoN.transpose();
        }
      } else if (const auto* gga = g->getMsgByClassPtr<gnss::Message_NMEA_GGA>()) {
        f.pos = {gga->fields.latitude_degrees * M_PI / 180, gga->fields.longitude_degrees * M_PI / 180,
                 gga->fields.altitude_meters + gga->fields.geoidal_distance * 0.0};
      } else {
        throw Error(where(label, t) + ": GNSS entry has neither a TOPCON_PZS nor an NMEA GGA message");
      }
      checkPlausible(rec, label, t);  // a place on Earth (non-finite included), heights, velocity, sigmas
      if (!haveOrigin && !fromCommentOrigin) {  // no origin in the comment: the first fix
        head.origin = f.pos;
        fromCommentOrigin = true;
      }
      emit(std::move(rec));
    } else {
      ++skipped;
    }
  }

  // The next record of a foreign recording: streams merged by time (equal times: GT, IMU, BARO, GNSS).
  bool nextForeign(RawlogRecord& out) {
    const Recording& d = *foreign;
    const bool hi = fi < d.imu.size(), hg = fg < d.gnss.size();
    if (!hi && !hg) return false;
    if (hi && (!hg || d.imu[fi].t <= d.gnss[fg].t)) {
      out.kind = RawlogRecord::Kind::Imu;
      out.imu = d.imu[fi++];
      out.t = out.imu.t;
    } else {
      out.kind = RawlogRecord::Kind::Gnss;
      out.gnss = d.gnss[fg++];
      out.t = out.gnss.t;
    }
    return true;
  }
};

RawlogReader::RawlogReader(const std::string& path, const RawlogReadOptions& opt) : impl_(std::make_unique<Impl>()) {
  InputScope scope(path);
  if (!std::filesystem::exists(path)) throw Error(path + ": rawlog not found");
  noteInput(path);  // an output replaced whole must not hold it (output.hpp)
  Impl& m = *impl_;
  m.path = path;
  m.head.source = path;
  // navimpact's own rawlogs start with their comment; anything else is read
  // as MRPT's drivers record (labels, sensor axes and sensorPose)
  // Entries through one 1 MiB buffer (MRPT's archive reads every field with its
  // own small Read() call), with the length caps and gzip checks of EntryReader.
  m.reader.emplace(path);
  const auto first = m.reader->next();
  const auto c = std::dynamic_pointer_cast<mrpt::obs::CObservationComment>(first);
  if (first && !(c && (c->text.empty() || c->text.find("navimpact_scenario") != std::string::npos))) {
    m.reader.reset();
    detail::EntryReader reader(path);
    m.foreign = detail::readForeignRawlog(reader, opt);
    Recording& f = *m.foreign;
    m.head.origin = f.origin;
    m.head.imu_rate_hz = f.imu_rate_hz;
    m.head.start_unix_s = f.start_unix_s;
    m.head.t_start_s = f.t_start_s;
    m.head.lever_arm_B = f.lever_arm_B;
    m.head.metadata = f.metadata;
    m.head.notices = f.notices;
    return;
  }
  // navimpact writes its labels (IMU, GNSS, ...): another label given for one
  // of its rawlogs would be ignored, so it is refused
  for (const auto& [given, own, flag] : {std::tuple{opt.imu_label, "IMU", "imu_label"}, {opt.gnss_label, "GNSS", "gnss_label"}})
    if (!given.empty() && given != own)
      throw Error(printable(path, 160) + ": a rawlog navimpact wrote: its " + own + " entries are labelled '" + own +
                  "', not '" + printable(given, 40) + "' (" + flag + " / --" + (own == std::string("IMU") ? "imu" : "gnss") +
                  "-label is for rawlogs other tools wrote)");
  if (!first) {
    m.end = true;
    return;
  }
  m.entry = m.reader->entry();
  m.readComment(*c);
}

RawlogReader::~RawlogReader() = default;

const Recording& RawlogReader::header() const { return impl_->head; }

bool RawlogReader::next(RawlogRecord& out) {
  Impl& m = *impl_;
  if (m.foreign) return m.nextForeign(out);
  m.readMore();
  if (m.ready.empty()) return false;
  out = std::move(m.ready.front());
  m.ready.pop_front();
  return true;
}

RawlogRecords readRawlogRecords(const std::string& path, const RawlogReadOptions& opt) {
  InputScope scope(path);
  RawlogReader reader(path, opt);
  RawlogRecords out;
  Recording& d = out.data;
  d = reader.header();
  RawlogRecord r;
  while (reader.next(r)) {
    switch (r.kind) {
      case RawlogRecord::Kind::Imu: d.imu.push_back(r.imu); break;
      case RawlogRecord::Kind::Gnss: d.gnss.push_back(r.gnss); break;
      case RawlogRecord::Kind::Baro: d.baro.push_back(r.baro); break;
      case RawlogRecord::Kind::Reference: d.reference.push_back(r.reference); break;
    }
    out.order.push_back(r.kind);
  }
  const Recording& h = reader.header();
  d.origin = h.origin;
  d.lever_arm_B = h.lever_arm_B;
  d.notices = h.notices;
  d.start_unix_s = h.start_unix_s;
  d.t_start_s = h.t_start_s;
  return out;
}

Recording readRawlog(const std::string& path, const RawlogReadOptions& opt) {
  return std::move(readRawlogRecords(path, opt).data);
}

bool RawlogRecordCursor::next(RawlogRecord& out) {
  if (pos_ >= r_.order.size()) return false;
  const Recording& d = r_.data;
  out.kind = r_.order[pos_++];
  switch (out.kind) {
    case RawlogRecord::Kind::Imu:
      out.imu = d.imu.at(imu_++);
      out.t = out.imu.t;
      break;
    case RawlogRecord::Kind::Gnss:
      out.gnss = d.gnss.at(gnss_++);
      out.t = out.gnss.t;
      break;
    case RawlogRecord::Kind::Baro:
      out.baro = d.baro.at(baro_++);
      out.t = out.baro.t;
      break;
    case RawlogRecord::Kind::Reference:
      out.reference = d.reference.at(ref_++);
      out.t = out.reference.t;
      break;
  }
  return true;
}

}  // namespace navimpact::rawlog
