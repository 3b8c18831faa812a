// Rawlogs navimpact did not write, made with MRPT's own classes the way its
// drivers fill them: IMU in sensor axes with the mounting in sensorPose (MRPT
// vehicle frame x forward, y left, z up), GNSS as NMEA GGA + RMC, Novatel
// BESTPOS or TOPCON PZS, sensory-frame or observation-only files, any labels.
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationGPS.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/serialization/CArchive.h>

#include <cstdio>
#include <cstring>
#include <random>

#include "navimpact/core/error.hpp"
#include "navimpact/rawlog/writer.hpp"
#include "test_support.hpp"

namespace {

using navimpact::Recording;
namespace gnss = mrpt::obs::gnss;
constexpr double kDeg = M_PI / 180.0;

struct Truth {
  std::vector<Eigen::Vector3d> w_B, f_B;  // body FRD
  std::vector<Eigen::Vector3d> v_N;       // GNSS velocity of each fix (kinds 3, 4: Novatel BESTVEL)
  Eigen::Matrix3d C_StoFRD;               // sensor axes -> body FRD
};

// An IMU mounted with a random attitude on the vehicle, recorded as a driver does:
// values in sensor axes, the mounting in sensorPose; GNSS with label gnssLabel.
Truth writeForeign(const std::string& path, std::uint64_t seed, bool sensoryFrames, const std::vector<std::string>& imuLabels,
                   int gnssKind) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> N(0.0, 1.0);
  std::uniform_real_distribution<double> U(-M_PI, M_PI);
  const double yaw = U(rng), pitch = U(rng) / 2, roll = U(rng);
  std::printf("seed %llu: mounting yaw %.3f pitch %.3f roll %.3f rad, %s, GNSS kind %d\n", (unsigned long long)seed, yaw,
              pitch, roll, sensoryFrames ? "sensory frames" : "observations", gnssKind);
  const mrpt::poses::CPose3D mount(0.1, 0.2, 0.3, yaw, pitch, roll);
  Eigen::Matrix3d R;  // sensor -> vehicle FLU
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) R(a, b) = mount.getRotationMatrix()(a, b);
  Truth t;
  t.C_StoFRD = Eigen::Vector3d(1, -1, -1).asDiagonal() * R;
  mrpt::io::CFileGZOutputStream out(path);
  auto arch = mrpt::serialization::archiveFrom(out);
  const auto t0 = mrpt::Clock::fromDouble(1.6e9 + 0.25);
  for (int k = 0; k < 200; ++k) {
    const auto ts = t0 + std::chrono::microseconds(10000 * k);
    std::vector<mrpt::obs::CObservation::Ptr> obs;
    const Eigen::Vector3d w(N(rng), N(rng), N(rng)), f(N(rng), N(rng), -9.8 + N(rng));
    t.w_B.push_back(w);
    t.f_B.push_back(f);
    for (const auto& label : imuLabels) {
      auto m = std::make_shared<mrpt::obs::CObservationIMU>();
      m->sensorLabel = label;
      m->timestamp = ts;
      m->sensorPose = mount;
      const Eigen::Vector3d ws = t.C_StoFRD.transpose() * w, fs = t.C_StoFRD.transpose() * f;
      m->set(mrpt::obs::IMU_WX, ws[0]);
      m->set(mrpt::obs::IMU_WY, ws[1]);
      m->set(mrpt::obs::IMU_WZ, ws[2]);
      m->set(mrpt::obs::IMU_X_ACC, fs[0]);
      m->set(mrpt::obs::IMU_Y_ACC, fs[1]);
      m->set(mrpt::obs::IMU_Z_ACC, fs[2]);
      m->set(mrpt::obs::IMU_YAW, 0.3);  // drivers add their own orientation estimates: ignored
      obs.push_back(m);
    }
    if (k % 20 == 5) {
      auto g = std::make_shared<mrpt::obs::CObservationGPS>();
      g->sensorLabel = "GPS";
      g->timestamp = ts;
      g->sensorPose = mrpt::poses::CPose3D(0.5, 0.25, 1.0, 0, 0, 0);  // antenna 0.5 fwd, 0.25 left, 1 up
      const double lat = 46.5 + 1e-5 * k, lon = 6.6, msl = 400.0 + k, und = 47.25;
      if (gnssKind == 0) {
        gnss::Message_NMEA_GGA gga;
        gga.fields.latitude_degrees = lat;
        gga.fields.longitude_degrees = lon;
        gga.fields.altitude_meters = msl;
        gga.fields.geoidal_distance = und;
        gga.fields.fix_quality = 1;
        g->setMsg(gga);
        gnss::Message_NMEA_RMC rmc;
        rmc.fields.validity_char = 'A';
        rmc.fields.speed_knots = 10.0;
        rmc.fields.direction_degrees = 30.0;
        g->setMsg(rmc);
      } else if (gnssKind == 1 || gnssKind == 3 || gnssKind == 4) {
        if (gnssKind != 1) {  // BESTVEL as MRPT's driver records it: a generic OEM6 frame, log 99
          std::uniform_real_distribution<double> Ur(0.0, 1.0);
          const double hor = 30.0 * Ur(rng), trk = 360.0 * Ur(rng), vert = 4.0 * (Ur(rng) - 0.5);
          t.v_N.push_back(Eigen::Vector3d(hor * std::cos(trk * kDeg), hor * std::sin(trk * kDeg), -vert));
          gnss::Message_NV_OEM6_GENERIC_FRAME v;
          v.header.msg_id = 99;
          v.header.hdr_len = 28;  // as a receiver fills it (MRPT sizes the body from msg_len)
          v.header.msg_len = 44;
          v.msg_body.assign(44, 0);
          const std::uint32_t status = 0, type = 8;  // SOL_COMPUTED, DOPPLER_VELOCITY
          const float latency = 0.0f, age = 0.5f;
          std::memcpy(v.msg_body.data(), &status, 4);
          std::memcpy(v.msg_body.data() + 4, &type, 4);
          std::memcpy(v.msg_body.data() + 8, &latency, 4);
          std::memcpy(v.msg_body.data() + 12, &age, 4);
          std::memcpy(v.msg_body.data() + 16, &hor, 8);
          std::memcpy(v.msg_body.data() + 24, &trk, 8);
          std::memcpy(v.msg_body.data() + 32, &vert, 8);
          // (setMsg needs a msg_type the generic frame lacks: into the map as the driver does)
          if (gnssKind == 3) {
            g->messages[gnss::NV_OEM6_GENERIC_FRAME].set(new gnss::Message_NV_OEM6_GENERIC_FRAME(v));
          } else {  // a GNSS entry of its own at the same time
            auto g2 = std::make_shared<mrpt::obs::CObservationGPS>();
            g2->sensorLabel = "GPS";
            g2->timestamp = ts;
            g2->messages[gnss::NV_OEM6_GENERIC_FRAME].set(new gnss::Message_NV_OEM6_GENERIC_FRAME(v));
            obs.push_back(g2);
          }
        }
        gnss::Message_NV_OEM6_BESTPOS b;
        b.fields.solution_stat = gnss::nv_oem6_solution_status::SOL_COMPUTED;
        b.fields.lat = lat;
        b.fields.lon = lon;
        b.fields.hgt = msl;
        b.fields.undulation = static_cast<float>(und);
        b.fields.lat_sigma = 0.5f;
        b.fields.lon_sigma = 0.75f;
        b.fields.hgt_sigma = 1.5f;
        g->setMsg(b);
      } else {
        gnss::Message_TOPCON_PZS p;
        p.latitude_degrees = lat;
        p.longitude_degrees = lon;
        p.height_meters = msl + und;
        p.Fix = 1;
        g->setMsg(p);
      }
      obs.push_back(g);
    }
    if (sensoryFrames) {
      mrpt::obs::CSensoryFrame sf;
      for (auto& o : obs) sf.insert(o);
      arch << sf;
    } else {
      for (auto& o : obs) arch << *o;
    }
  }
  return t;
}

std::string errorOf(const std::string& path, const navimpact::rawlog::RawlogReadOptions& opt) {
  try {
    navimpact::rawlog::readRawlog(path, opt);
  } catch (const navimpact::Error& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(ForeignRawlog, ImuInSensorAxesWithItsMountingComesBackInBodyFrd) {
  for (int kind = 0; kind < 3; ++kind)
    for (bool frames : {false, true}) {
      const auto p = (navimpact::test::tempDir() / ("f" + std::to_string(kind) + (frames ? "sf" : "obs") + ".rawlog")).string();
      const Truth t = writeForeign(p, 4200 + 2 * kind + frames, frames, {"XSENS"}, kind);
      const Recording d = navimpact::rawlog::readRawlog(p);
      ASSERT_EQ(d.imu.size(), t.w_B.size());
      for (std::size_t k = 0; k < d.imu.size(); ++k) {
        EXPECT_LT((d.imu[k].w_IB_B - t.w_B[k]).norm(), 1e-12) << k;
        EXPECT_LT((d.imu[k].f_B - t.f_B[k]).norm(), 1e-12) << k;
        EXPECT_NEAR(d.imu[k].t - d.imu[0].t, 0.01 * k, 1e-9);
      }
      EXPECT_NEAR(d.imu_rate_hz, 100.0, 1e-6);
      EXPECT_NEAR(double(d.start_unix_s) - d.t_start_s, 1.6e9 + 0.25, 1e-6);  // time zero = first entry
      ASSERT_EQ(d.gnss.size(), 10u);
      const auto& f = d.gnss[0];
      EXPECT_NEAR(f.t, 0.05, 1e-9);
      EXPECT_NEAR(f.pos.lat, (46.5 + 5e-5) * kDeg, 1e-12);
      EXPECT_NEAR(f.pos.h, 405.0 + 47.25, 1e-6);  // ellipsoidal: MSL + undulation
      ASSERT_TRUE(d.lever_arm_B);
      EXPECT_LT((*d.lever_arm_B - Eigen::Vector3d(0.5, -0.25, -1.0)).norm(), 1e-15);
      if (kind == 0) {  // RMC: 10 kn at 30 deg, horizontal only
        ASSERT_TRUE(f.v_N && f.cov_vel_N);
        EXPECT_NEAR((*f.v_N)[0], 10 * 1852.0 / 3600 * std::cos(30 * kDeg), 1e-12);
        EXPECT_NEAR((*f.v_N)[1], 10 * 1852.0 / 3600 * std::sin(30 * kDeg), 1e-12);
        EXPECT_GE((*f.cov_vel_N)(2, 2), 1e4);
        EXPECT_FALSE(f.cov_pos_N);
      } else if (kind == 1) {  // BESTPOS sigmas
        ASSERT_TRUE(f.cov_pos_N);
        EXPECT_NEAR((*f.cov_pos_N)(1, 1), 0.75 * 0.75, 1e-7);
        EXPECT_FALSE(f.v_N);
      } else {
        EXPECT_FALSE(f.v_N);
      }
    }
}

// Novatel BESTVEL has no MRPT 2.5 class: MRPT's driver stores it as a generic
// OEM6 frame, whose deserialisation reads 4 bytes of the body instead of its
// length (libs/obs/src/gnss_messages_novatel.cpp, internal_readFromStream), so
// MRPT cannot read such an entry back. The reader refuses it in one line naming
// the entry, whether the frame shares the BESTPOS entry or has its own.
TEST(ForeignRawlog, NovatelGenericFramesAreRefusedNamingTheEntry) {
  for (int kind : {3, 4}) {
    const auto p = (navimpact::test::tempDir() / ("bv" + std::to_string(kind) + ".rawlog")).string();
    writeForeign(p, 4400 + kind, false, {"XSENS"}, kind);
    const std::string e = errorOf(p, {});
    EXPECT_NE(e.find("bv" + std::to_string(kind) + ".rawlog: entry "), std::string::npos) << e;
    EXPECT_NE(e.find("CObservationGPS"), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(ForeignRawlog, SeveralImuLabelsNeedAChoiceListingThem) {
  const auto p = (navimpact::test::tempDir() / "two.rawlog").string();
  const Truth t = writeForeign(p, 4300, false, {"IMU_A", "IMU_B"}, 0);
  const std::string e = errorOf(p, {});
  EXPECT_NE(e.find("two.rawlog: several IMU labels: IMU_A (200), IMU_B (200); choose one with --imu-label"),
            std::string::npos) << e;
  const Recording d = navimpact::rawlog::readRawlog(p, {"IMU_B", ""});
  ASSERT_EQ(d.imu.size(), 200u);
  EXPECT_LT((d.imu[7].w_IB_B - t.w_B[7]).norm(), 1e-12);
  const std::string e2 = errorOf(p, {"IMU_C", ""});
  EXPECT_NE(e2.find("no IMU entries with label 'IMU_C' (labels found: IMU_A (200), IMU_B (200))"), std::string::npos) << e2;
  const std::string e3 = errorOf(p, {"IMU_A", "GNSS"});
  EXPECT_NE(e3.find("no GNSS entries with label 'GNSS' (labels found: GPS (10))"), std::string::npos) << e3;
}

// A rawlog navimpact wrote keeps its own convention (FRD data, identity sensorPose).
TEST(ForeignRawlog, NavimpactRawlogsAreNotTurned) {
  const Recording b = navimpact::rawlog::readRawlog(navimpact::test::sourcePath("datasets/uav_flight_260s_ref.rawlog"));
  ASSERT_EQ(b.imu.size(), 52000u);
  EXPECT_LT(b.imu[0].f_B[2], -3.0);  // specific force points up: negative along body down (not turned to FLU)
}

// Entries of classes navimpact does not read are decoded with stderr silenced:
// MRPT prints warnings of its own while decoding some of them (a 3D range scan
// whose image size disagrees with its camera: "autofixing incorrect camera
// resolution"), and the readers print nothing. The IMU and GNSS around them
// are read as usual, and stderr works again afterwards.
TEST(ForeignRawlog, EntriesOfOtherClassesPrintNothing) {
  const std::string p = navimpact::test::tempDir() / "with_3d_scan.rawlog";
  writeForeign(p, 5, false, {"IMU"}, 0);
  {
    mrpt::io::CFileGZOutputStream out(p, mrpt::io::OpenMode::APPEND);  // a second gzip member
    auto arch = mrpt::serialization::archiveFrom(out);
    mrpt::obs::CObservation3DRangeScan scan;
    scan.sensorLabel = "KINECT";
    scan.timestamp = mrpt::Clock::fromDouble(1.6e9 + 1.0);
    scan.hasRangeImage = true;
    scan.rangeImage.setZero(4, 6);
    scan.cameraParams.ncols = 640;  // disagrees with the 6 x 4 image
    scan.cameraParams.nrows = 480;
    arch << scan;
  }
  testing::internal::CaptureStderr();
  const Recording r = navimpact::rawlog::readRawlog(p);
  std::fprintf(stderr, "after");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "after");
  EXPECT_EQ(r.imu.size(), 200u);
}

// A foreign rawlog's records pass the physical ranges every reader applies
// (found by a review: navimpact's own rawlogs were checked, foreign ones not):
// an angular rate of 1e6 rad/s or a GGA latitude of 200 deg is refused naming
// the entry and the label; the same rawlog with plausible values reads.
TEST(ForeignRawlog, ValuesOutsideThePhysicalRangesAreRefusedNamingTheEntry) {
  for (int bad = 0; bad < 3; ++bad) {
    const auto p = (navimpact::test::tempDir() / ("range" + std::to_string(bad) + ".rawlog")).string();
    {
      mrpt::io::CFileGZOutputStream out(p);
      auto arch = mrpt::serialization::archiveFrom(out);
      const auto t0 = mrpt::Clock::fromDouble(1.6e9);
      for (int k = 0; k < 4; ++k) {
        mrpt::obs::CObservationIMU m;
        m.sensorLabel = "IMU";
        m.timestamp = t0 + std::chrono::milliseconds(10 * k);
        const double w = bad == 1 && k == 2 ? 1e6 : 0.1;
        for (auto q : {mrpt::obs::IMU_WX, mrpt::obs::IMU_WY, mrpt::obs::IMU_WZ}) m.set(q, w);
        for (auto q : {mrpt::obs::IMU_X_ACC, mrpt::obs::IMU_Y_ACC}) m.set(q, 0.0);
        m.set(mrpt::obs::IMU_Z_ACC, 9.8);
        arch << m;
        if (k == 1) {
          mrpt::obs::CObservationGPS g;
          g.sensorLabel = "GPS";
          g.timestamp = m.timestamp;
          gnss::Message_NMEA_GGA gga;
          gga.fields.latitude_degrees = bad == 2 ? 200.0 : 46.5;
          gga.fields.longitude_degrees = 6.6;
          gga.fields.altitude_meters = 400.0;
          gga.fields.fix_quality = 1;
          g.setMsg(gga);
          arch << g;
        }
      }
    }
    const std::string m = errorOf(p, {});
    if (bad == 0) {
      EXPECT_EQ(m, "(no error)");
    } else {
      EXPECT_EQ(m.rfind(p + ": entry " + std::to_string(bad == 1 ? 3 : 2) + " (label " + (bad == 1 ? "IMU" : "GPS") + "): ", 0), 0u)
          << m;
      EXPECT_NE(m.find(bad == 1 ? "angular rate" : "not a place on Earth"), std::string::npos) << m;
    }
  }
}
