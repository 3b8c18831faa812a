// Import of a run from a manifest: random runs written in random units, axes,
// time bases and datums come back as the SI / FRD / NED / ellipsoidal truth;
// every bad input is one error naming the file, the line and the key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

#include "navimpact/core/earth.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/import/manifest.hpp"
#include "test_support.hpp"

namespace navimpact {
namespace {

using units::kDeg;
namespace fs = std::filesystem;

void writeFile(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

std::string g17(double x) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

/// A random proper signed permutation C (body = C * file) and its manifest text.
Eigen::Matrix3d randomAxes(std::mt19937_64& rng, std::string& text) {
  int perm[3] = {0, 1, 2};
  std::shuffle(perm, perm + 3, rng);
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) C(i, perm[i]) = (rng() & 1) ? 1.0 : -1.0;
  if (C.determinant() < 0) C.row(2) *= -1.0;
  text = "[";
  for (int i = 0; i < 3; ++i) text += std::string(i ? ", " : "") + (C(i, perm[i]) < 0 ? "-" : "") + char('x' + perm[i]);
  text += "]";
  return C;
}

struct TrueRun {
  Eigen::Matrix3d C;
  std::vector<double> t_imu, t_gnss, t_ref;   // the files' time axis [s] (before offsets)
  std::vector<Eigen::Vector3d> w_B, f_B;
  std::vector<earth::Geodetic> gnss, ref;     // ellipsoidal
  std::vector<Eigen::Vector3d> v_N, sig;
  std::vector<Eigen::Vector3d> rpy;
  double off_gnss = 0, off_ref = 0, undulation = 0;
  std::optional<double> zero_unix;
  Eigen::Vector3d lever;
  bool increments = false;
};

// One random run, written to @p dir; returns its manifest's path and the truth.
std::string randomRun(std::uint64_t seed, TrueRun& run, const fs::path& dir) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> N(0.0, 1.0);
  const double rate = 50.0 * std::pow(20.0, U(rng));  // 50..1000 Hz
  const std::size_t n = 400;
  std::string axesText;
  run.C = randomAxes(rng, axesText);
  const char* gyroUnits[] = {"rad/s", "deg/s", "deg/h", "mrad/s"};
  const double gyroF[] = {1.0, kDeg, kDeg / 3600.0, 1e-3};
  const char* accUnits[] = {"m/s2", "g", "mg"};
  const double accF[] = {1.0, units::kG0, units::kG0 * 1e-3};
  const char* gyroInc[] = {"rad", "deg", "mrad"};
  const double gyroIncF[] = {1.0, kDeg, 1e-3};
  const char* timeUnits[] = {"s", "ms", "us", "ns"};
  const double timeF[] = {1.0, 1e-3, 1e-6, 1e-9};
  const int gu = int(rng() % 4), au = int(rng() % 3), tu = int(rng() % 4), gi = int(rng() % 3);
  const bool gyroIncrements = rng() & 1, accIncrements = rng() & 1, byRate = (rng() % 3) == 0;
  run.increments = gyroIncrements || accIncrements;
  const bool enu = rng() & 1, rad = rng() & 1, sigmaColumns = rng() & 1;
  run.off_gnss = -5.0 + 10.0 * U(rng);
  run.off_ref = -1.0 + 2.0 * U(rng);
  run.undulation = -100.0 + 200.0 * U(rng);
  if (rng() & 1) run.zero_unix = std::floor(1e9 + 1e9 * U(rng)) + U(rng);
  run.lever = Eigen::Vector3d(N(rng), N(rng), N(rng));
  const double t0 = 1000.0 * U(rng);
  std::printf("seed %llu: rate %.3f Hz, axes %s, gyro %s%s, acc %s%s, time %s, gnss offset %.3f s, "
              "undulation %.2f m, velocity %s, angles %s, sigma %s, zero_unix %s\n",
              (unsigned long long)seed, rate, axesText.c_str(), gyroIncrements ? "increments " : "",
              gyroIncrements ? gyroInc[gi] : gyroUnits[gu], accIncrements ? "increments " : "",
              accIncrements ? "m/s" : accUnits[au], byRate ? "rate" : timeUnits[tu], run.off_gnss, run.undulation,
              enu ? "ENU" : "NED", rad ? "rad" : "deg", sigmaColumns ? "columns" : "constant",
              run.zero_unix ? g17(*run.zero_unix).c_str() : "none");

  std::ostringstream imu;
  imu << "time,gx,gy,gz,ax,ay,az\n";
  for (std::size_t k = 0; k < n; ++k) {
    // a jittered clock unless the rate stands for the time column
    const double t = byRate ? k / rate : t0 + (k + 0.2 * (U(rng) - 0.5)) / rate;
    const double dt = k == 0 ? 1.0 / rate : t - run.t_imu.back();
    run.t_imu.push_back(t);
    const Eigen::Vector3d w(0.5 * N(rng), 0.5 * N(rng), 0.5 * N(rng)), f(N(rng), N(rng), 9.8 + N(rng));
    run.w_B.push_back(w);
    run.f_B.push_back(f);
    const Eigen::Vector3d wf = run.C.transpose() * w / (gyroIncrements ? gyroIncF[gi] / dt : gyroF[gu]);
    const Eigen::Vector3d ff = run.C.transpose() * f / (accIncrements ? 1.0 / dt : accF[au]);
    imu << g17(t / timeF[tu]) << "," << g17(wf[0]) << "," << g17(wf[1]) << "," << g17(wf[2]) << "," << g17(ff[0])
        << "," << g17(ff[1]) << "," << g17(ff[2]) << "\n";
  }
  std::ostringstream gnss, ref;
  gnss << "t,lat,lon,h,vn,ve,vd,sn,se,sd\n";
  ref << "t;lat;lon;h;roll;pitch;yaw\n";
  const double lat0 = (-80.0 + 160.0 * U(rng)) * kDeg, lon0 = (-180.0 + 360.0 * U(rng)) * kDeg;
  const double a = rad ? 1.0 : 1.0 / kDeg;
  for (int k = 0; k < 20; ++k) {
    const double t = (byRate ? 0.0 : t0) + 0.1 * k + 0.05 * U(rng);
    const earth::Geodetic p{lat0 + 1e-5 * N(rng), lon0 + 1e-5 * N(rng), 100.0 * U(rng)};
    const Eigen::Vector3d v(N(rng), N(rng), 0.1 * N(rng)), s(0.1 + U(rng), 0.1 + U(rng), 0.2 + U(rng));
    run.t_gnss.push_back(t);
    run.gnss.push_back(p);
    run.v_N.push_back(v);
    run.sig.push_back(sigmaColumns ? s : Eigen::Vector3d(1.5, 1.5, 3.0));
    const Eigen::Vector3d vf = enu ? Eigen::Vector3d(v[1], v[0], -v[2]) : v;
    gnss << g17(t) << "," << g17(p.lat * a) << "," << g17(p.lon * a) << "," << g17(p.h - run.undulation) << ","
         << g17(vf[0]) << "," << g17(vf[1]) << "," << g17(vf[2]) << "," << g17(s[0]) << "," << g17(s[1]) << ","
         << g17(s[2]) << "\n";
    const Eigen::Vector3d rpy(0.3 * N(rng), 0.3 * N(rng), -3.0 + 6.0 * U(rng));
    run.t_ref.push_back(t);
    run.ref.push_back(p);
    run.rpy.push_back(rpy);
    ref << g17(t) << ";" << g17(p.lat * a) << ";" << g17(p.lon * a) << ";" << g17(p.h) << ";" << g17(rpy[0] / kDeg)
        << ";" << g17(rpy[1] / kDeg) << ";" << g17(rpy[2] / kDeg) << "\n";
  }
  writeFile(dir / "imu.csv", imu.str());
  writeFile(dir / "gnss.csv", gnss.str());
  writeFile(dir / "ref.csv", ref.str());
  std::ostringstream m;
  m << "imu:\n  file: imu.csv\n";
  if (byRate) m << "  time: {rate_hz: " << g17(rate) << "}\n";
  else m << "  time: {column: time, unit: " << timeUnits[tu] << "}\n";
  m << "  gyro: {columns: [gx, gy, gz], " << (gyroIncrements ? std::string("increments: ") + gyroInc[gi] : std::string("unit: ") + gyroUnits[gu]) << "}\n";
  m << "  acc: {columns: [ax, ay, az], " << (accIncrements ? std::string("increments: m/s") : std::string("unit: ") + accUnits[au]) << "}\n";
  m << "  axes: " << axesText << "\n";
  m << "gnss:\n  file: gnss.csv\n  time: {column: t, unit: s}\n"
    << "  position: {lat: lat, lon: lon, height: h, angle_unit: " << (rad ? "rad" : "deg") << "}\n"
    << "  height_datum: {geoid_undulation_m: " << g17(run.undulation) << "}\n"
    << "  velocity: {columns: [vn, ve, vd], frame: " << (enu ? "ENU" : "NED") << ", unit: m/s}\n"
    << (sigmaColumns ? "  sigma: {columns: [sn, se, sd], unit: m}\n" : "  sigma: {horizontal_m: 1.5, vertical_m: 3.0}\n")
    << "  lever_arm_m: [" << g17(run.lever[0]) << ", " << g17(run.lever[1]) << ", " << g17(run.lever[2]) << "]\n";
  m << "reference:\n  file: ref.csv\n  delimiter: \";\"\n  time: {column: t, unit: s}\n"
    << "  position: {lat: lat, lon: lon, height: h, angle_unit: " << (rad ? "rad" : "deg") << "}\n"
    << "  height_datum: ellipsoid\n  attitude: {roll: roll, pitch: pitch, yaw: yaw, unit: deg}\n";
  m << "time_offset_s: {gnss: " << g17(run.off_gnss) << ", reference: " << g17(run.off_ref) << "}\n";
  if (run.zero_unix) m << "time_zero_unix_s: " << g17(*run.zero_unix) << "\n";
  writeFile(dir / "run.yaml", m.str());
  return (dir / "run.yaml").string();
}

// Found by the intake probe: a tab written as YAML writes it ("\t", or '\t'
// in single quotes) was refused although `tab` was accepted. All three read
// the same tab-separated file as the ';' file it was made from.
TEST(ImportManifest, ATabDelimiterMaybeWrittenAsYamlWritesIt) {
  auto slurp = [](const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
  };
  for (std::uint64_t seed = 20261130;; ++seed) {
    const fs::path dir = test::tempDir() / ("tab" + std::to_string(seed));
    fs::create_directories(dir);
    TrueRun run;
    const std::string manifest = randomRun(seed, run, dir);
    Recording semi;
    try {
      semi = import::importManifest(manifest);
    } catch (const Error&) {
      continue;  // a stream drawn outside the IMU's span (tested above): the next seed
    }
    std::string ref = slurp(dir / "ref.csv"), yaml = slurp(manifest);
    std::replace(ref.begin(), ref.end(), ';', '\t');
    writeFile(dir / "ref.csv", ref);
    const std::string semiKey = "delimiter: \";\"";
    ASSERT_NE(yaml.find(semiKey), std::string::npos);
    for (const std::string tab : {"\"\\t\"", "'\\t'", "tab"}) {
      std::string y = yaml;
      y.replace(y.find(semiKey), semiKey.size(), "delimiter: " + tab);
      writeFile(manifest, y);
      const Recording d = import::importManifest(manifest);
      ASSERT_EQ(d.reference.size(), semi.reference.size()) << tab;
      for (std::size_t k = 0; k < d.reference.size(); ++k) {
        EXPECT_EQ(d.reference[k].t, semi.reference[k].t) << tab;
        EXPECT_EQ(d.reference[k].p_L, semi.reference[k].p_L) << tab;
      }
    }
    {
      std::string y = yaml;
      y.replace(y.find(semiKey), semiKey.size(), "delimiter: \"\\n\"");
      writeFile(manifest, y);
      try {
        import::importManifest(manifest);
        ADD_FAILURE() << "a line break accepted as delimiter";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("reference.delimiter"), std::string::npos) << e.what();
      }
    }
    break;
  }
}

// Velocity sigma columns are in the velocity's own frame order: an ENU
// velocity's [se, sn, su] become sigmas about N, E, D (found by a probe: they
// were read as N, E, D whatever the frame). The run's position sigma columns
// (N, E, D) serve as velocity sigmas, listed in the frame's order; the fixes'
// velocity covariance must be their squares about N, E, D.
TEST(ImportManifest, VelocitySigmaColumnsFollowTheVelocitysFrame) {
  auto slurp = [](const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
  };
  bool seen[2] = {false, false};  // NED, ENU
  for (std::uint64_t seed = 20261130; !(seen[0] && seen[1]) && seed < 20261130 + 200; ++seed) {
    const fs::path dir = test::tempDir() / ("vsig" + std::to_string(seed));
    fs::create_directories(dir);
    TrueRun run;
    const std::string manifest = randomRun(seed, run, dir);
    std::string yaml = slurp(manifest);
    if (yaml.find("sigma: {columns: [sn, se, sd]") == std::string::npos) continue;  // constant position sigma
    const bool enu = yaml.find("frame: ENU") != std::string::npos;
    if (seen[enu]) continue;
    const std::string unitKey = "frame: " + std::string(enu ? "ENU" : "NED") + ", unit: m/s}";
    ASSERT_NE(yaml.find(unitKey), std::string::npos);
    yaml.replace(yaml.find(unitKey), unitKey.size(),
                 "frame: " + std::string(enu ? "ENU" : "NED") + ", unit: m/s, sigma: {columns: " +
                     (enu ? "[se, sn, sd]" : "[sn, se, sd]") + ", unit: m/s}}");
    writeFile(manifest, yaml);
    Recording d;
    try {
      d = import::importManifest(manifest);
    } catch (const Error&) {
      continue;  // a stream drawn outside the IMU's span: the next seed
    }
    seen[enu] = true;
    ASSERT_EQ(d.gnss.size(), run.sig.size());
    for (std::size_t k = 0; k < d.gnss.size(); ++k) {
      ASSERT_TRUE(d.gnss[k].cov_vel_N.has_value());
      const Eigen::Vector3d var = d.gnss[k].cov_vel_N->diagonal();
      for (int a = 0; a < 3; ++a)
        EXPECT_NEAR(var[a], run.sig[k][a] * run.sig[k][a], 1e-12 * run.sig[k][a] * run.sig[k][a])
            << (enu ? "ENU" : "NED") << " fix " << k << " axis " << a;
    }
  }
  EXPECT_TRUE(seen[0] && seen[1]);
}

TEST(ImportManifest, RandomRunsComeBackAsTheirTruth) {
  const std::uint64_t base = 20261124;
  for (std::uint64_t s = 0; s < 24; ++s) {
    const fs::path dir = test::tempDir() / ("run" + std::to_string(s));
    fs::create_directories(dir);
    TrueRun run;
    const std::string manifest = randomRun(base + s, run, dir);
    // an aiding stream with no record inside the IMU's time span (its time
    // offset drawn over +-5 s, the IMU's span 0.4-8 s) is refused, naming its file
    const double imuA = run.t_imu.front(), imuB = run.t_imu.back();
    auto overlaps = [&](const std::vector<double>& t, double off) { return t.back() + off >= imuA && t.front() + off <= imuB; };
    const bool gnssIn = overlaps(run.t_gnss, run.off_gnss), refIn = overlaps(run.t_ref, run.off_ref);
    std::printf("  gnss %s, reference %s the IMU's span\n", gnssIn ? "within" : "outside", refIn ? "within" : "outside");
    if (!gnssIn || !refIn) {
      try {
        import::importManifest(manifest);
        ADD_FAILURE() << "a stream outside the IMU's time span accepted";
      } catch (const Error& e) {
        const std::string m = e.what(), file = (dir / (gnssIn ? "ref.csv" : "gnss.csv")).string();
        EXPECT_EQ(m.rfind(file + ": no record of stream " + (gnssIn ? "reference" : "gnss") + " lies within the IMU's time span", 0), 0u) << m;
      }
      continue;
    }
    const Recording d = import::importManifest(manifest);
    ASSERT_EQ(d.imu.size(), run.t_imu.size());
    ASSERT_EQ(d.gnss.size(), run.gnss.size());
    ASSERT_EQ(d.reference.size(), run.ref.size());
    // one time axis: absolute time = start_unix_s + t = zero + file time + offset
    const double zero = run.zero_unix.value_or(0.0);
    auto abs = [&](double t) { return static_cast<double>(d.start_unix_s) + t; };
    if (run.zero_unix) {
      EXPECT_GE(d.imu.front().t, 0.0);
      EXPECT_LT(std::min({d.imu.front().t, d.gnss.front().t, d.reference.front().t}), 1.0);
    }
    for (std::size_t k = 0; k < d.imu.size(); ++k) {
      // the first increment's interval is not in the file: divided by the nominal step (checked below)
      if (k == 0 && run.increments) continue;
      EXPECT_NEAR(abs(d.imu[k].t), zero + run.t_imu[k], 1e-6 + 1e-15 * std::abs(zero + run.t_imu[k])) << k;
      EXPECT_LT((d.imu[k].w_IB_B - run.w_B[k]).norm(), 1e-12 * (1 + run.w_B[k].norm()) + 1e-9) << k;
      EXPECT_LT((d.imu[k].f_B - run.f_B[k]).norm(), 1e-12 * (1 + run.f_B[k].norm()) + 1e-9) << k;
    }
    for (std::size_t k = 0; k < d.gnss.size(); ++k) {
      const auto& f = d.gnss[k];
      EXPECT_NEAR(abs(f.t), zero + run.t_gnss[k] + run.off_gnss, 1e-6);
      EXPECT_NEAR(f.pos.lat, run.gnss[k].lat, 1e-14);
      EXPECT_NEAR(f.pos.lon, run.gnss[k].lon, 1e-14);
      EXPECT_NEAR(f.pos.h, run.gnss[k].h, 1e-9);
      ASSERT_TRUE(f.v_N && f.cov_pos_N);
      EXPECT_LT((*f.v_N - run.v_N[k]).norm(), 1e-12);
      EXPECT_LT((f.cov_pos_N->diagonal().cwiseSqrt() - run.sig[k]).norm(), 1e-12);
    }
    ASSERT_TRUE(d.lever_arm_B);
    EXPECT_LT((*d.lever_arm_B - run.lever).norm(), 1e-15);
    EXPECT_NEAR(d.origin.lat, run.ref[0].lat, 1e-15);
    for (std::size_t k = 0; k < d.reference.size(); ++k) {
      const auto& r = d.reference[k];
      EXPECT_NEAR(abs(r.t), zero + run.t_ref[k] + run.off_ref, 1e-6);
      EXPECT_LT((r.p_L - earth::geodeticToNed(run.ref[0], run.ref[k])).norm(), 1e-6);
      ASSERT_TRUE(r.q_BtoN);
      // C_BtoN = R3(yaw) R2(pitch) R1(roll) applied to body axes: x_B of a level body points at the yaw
      const Eigen::Matrix3d C = r.q_BtoN->toRotationMatrix();
      const double roll = std::atan2(C(2, 1), C(2, 2)), pitch = -std::asin(C(2, 0)), yaw = std::atan2(C(1, 0), C(0, 0));
      EXPECT_NEAR(roll, run.rpy[k][0], 1e-12);
      EXPECT_NEAR(pitch, run.rpy[k][1], 1e-12);
      EXPECT_NEAR(std::remainder(yaw - run.rpy[k][2], 2 * M_PI), 0.0, 1e-12);
    }
    EXPECT_NE(d.metadata.find("navimpact_scenario"), std::string::npos);
  }
}

// ---------------------------------------------------------------------------
// Bad input: a valid run, then one defect at a time.
// ---------------------------------------------------------------------------

const char* kImu =
    "t_s,gx,gy,gz,ax,ay,az\n"
    "0.00,0.1,0.2,0.3,0.1,0.2,9.8\n"
    "0.01,0.1,0.2,0.3,0.1,0.2,9.8\n"
    "0.02,0.1,0.2,0.3,0.1,0.2,9.8\n"
    "0.03,0.1,0.2,0.3,0.1,0.2,9.8\n";
const char* kGnss =
    "t_s,lat,lon,h\n"
    "0.00,46.5,6.6,400\n"
    "0.02,46.5,6.6,400\n";
const char* kManifest =
    "imu:\n"
    "  file: imu.csv\n"
    "  time: {column: t_s, unit: s}\n"
    "  gyro: {columns: [gx, gy, gz], unit: rad/s}\n"
    "  acc: {columns: [ax, ay, az], unit: m/s2}\n"
    "  axes: [x, y, z]\n"
    "gnss:\n"
    "  file: gnss.csv\n"
    "  time: {column: t_s, unit: s}\n"
    "  position: {lat: lat, lon: lon, height: h, angle_unit: deg}\n"
    "  height_datum: ellipsoid\n";

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

std::string importError(const std::string& manifest, const std::string& imu = kImu, const std::string& gnss = kGnss) {
  const fs::path dir = test::tempDir();
  writeFile(dir / "m.yaml", manifest);
  writeFile(dir / "imu.csv", imu);
  writeFile(dir / "gnss.csv", gnss);
  try {
    import::importManifest((dir / "m.yaml").string());
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ImportManifest, TheValidRunImports) {
  EXPECT_EQ(importError(kManifest), "(no error)");
}

TEST(ImportManifest, ManifestErrorsNameTheKey) {
  struct Case {
    std::string manifest, expect;
  } cases[] = {
      {replaced(kManifest, "  axes:", "  axis: [x, y, z]\n  axes:"), "m.yaml: key 'imu.axis': unknown key"},
      {replaced(kManifest, "  axes: [x, y, z]\n", "  axes: [x, y, z]\n  axes: [x, y, z]\n"), "key 'imu.axes': duplicate key (line"},
      {replaced(kManifest, "unit: rad/s", "unit: rpm"), "key 'imu.gyro.unit'"},
      {replaced(kManifest, "unit: m/s2", "unit: m/s"), "key 'imu.acc.unit'"},
      {replaced(kManifest, "unit: rad/s", "unit: rad/s, increments: rad"), "key 'imu.gyro': give exactly one"},
      {replaced(kManifest, "[x, y, z]", "[x, -y, z]"), "key 'imu.axes': is a mirror"},
      {replaced(kManifest, "[x, y, z]", "[x, x, z]"), "key 'imu.axes': axis 'x' is used twice"},
      {replaced(kManifest, "[x, y, z]", "[x, y, w]"), "key 'imu.axes[2]': 'w' is not an axis"},
      {replaced(kManifest, "[x, y, z]", "[[1, 0, 0], [0, 1, 0], [0, 0.5, 1]]"), "key 'imu.axes': is not a rotation matrix"},
      {replaced(kManifest, "angle_unit: deg", "angle_unit: grad"), "key 'gnss.position.angle_unit': must be one of deg, rad, got 'grad'"},
      {replaced(kManifest, "height_datum: ellipsoid", "height_datum: geoid"), "key 'gnss.height_datum'"},
      {replaced(kManifest, "  height_datum: ellipsoid\n", ""), "key 'gnss.height_datum': missing"},
      {replaced(kManifest, "{column: t_s, unit: s}", "{column: t_s}"), "key 'imu.time.unit': missing"},
      {replaced(kManifest, "{column: t_s, unit: s}", "{column: t_s, unit: h}"), "key 'imu.time.unit'"},
      {std::string(kManifest) + "time_offset_s: {gnss: abc}\n", "key 'time_offset_s.gnss': must be a number in [-1e+06, 1e+06] s, got 'abc'"},
      {std::string(kManifest) + "gnss2: {}\n", "key 'gnss2': unknown key"},
      {std::string(kManifest) + "time_offset_s: {baro: 1000}\n", "key 'time_offset_s.baro': the manifest has no baro stream"},
      {replaced(kManifest, "  file: gnss.csv\n", "  file: gnss.csv\n  lever_arm_m: [0, 0]\n"), "key 'gnss.lever_arm_m'"},
      {replaced(kManifest, "imu:", "imu: [\n"), "m.yaml:"},
  };
  for (const auto& c : cases) {
    const std::string e = importError(c.manifest);
    EXPECT_NE(e.find(c.expect), std::string::npos) << "expected '" << c.expect << "' in: " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(ImportManifest, DataErrorsNameFileLineAndKey) {
  struct Case {
    std::string imu, gnss, manifest, expect;
  } cases[] = {
      {replaced(kImu, "gx,", "gq,"), kGnss, kManifest, "imu.csv:1: no column 'gx' (key imu.gyro.columns[0])"},
      {replaced(kImu, "0.01,0.1", "0.01,nan"), kGnss, kManifest, "imu.csv:3: column 'gx' (key imu.gyro.columns[0]): value is nan"},
      {replaced(kImu, "0.01,0.1", "0.01,abc"), kGnss, kManifest, "imu.csv:3: column 'gx' (key imu.gyro.columns[0]): 'abc' is not a number"},
      {replaced(kImu, "0.02,", "0.005,"), kGnss, kManifest, "imu.csv:4: column 't_s' (key imu.time.column): time goes backwards"},
      {replaced(kImu, "0.02,", "0.01,"), kGnss, kManifest, "imu.csv:4: column 't_s' (key imu.time.column): time repeats"},
      {replaced(kImu, "0.03,", "0.09,"), kGnss, kManifest, "imu.csv:5: column 't_s' (key imu.time.column): gap of"},
      {replaced(kImu, "0.03,0.1,0.2,0.3,0.1,0.2,9.8", "0.03,0.1,0.2"), kGnss, kManifest, "imu.csv:5: missing fields"},
      {kImu, replaced(kGnss, "0.02,46.5", "0.02,146.5"), kManifest, "gnss.csv:3: column key gnss.position.lat: latitude 146.5"},
      {kImu, replaced(kGnss, "0.02,", "1.02,"), replaced(kManifest, "  height_datum: ellipsoid\n", "  height_datum: ellipsoid\n  max_gap_s: 0.5\n"),
       "gnss.csv:3: column 't_s' (key gnss.time.column): gap of 1.02 s after line 2 exceeds gnss.max_gap_s = 0.5 s"},
      {kImu, "t_s,lat,lon\n", kManifest, "gnss.csv:1: no column 'h' (key gnss.position.height)"},
      {"", kGnss, kManifest, "imu.csv: file is empty"},
      // values beyond any sensor or vehicle (recording.hpp), refused at their line
      // instead of written into a rawlog that no reader takes back
      {replaced(kImu, "0.01,0.1", "0.01,2000"), kGnss, kManifest,
       "imu.csv:3: keys imu.gyro, imu.acc: angular rate x = 2000 rad/s is beyond any IMU (|value| <= 1000 rad/s) (are the units right?)"},
      {replaced(kImu, "0.02,0.1,0.2,0.3,0.1,0.2,9.8", "0.02,0.1,0.2,0.3,0.1,0.2,1e7"), kGnss, kManifest,
       "imu.csv:4: keys imu.gyro, imu.acc: specific force z = 1e+07 m/s^2 is beyond any IMU"},
      {replaced(kImu, "0.00,", "-1e11,"), kGnss, kManifest,
       "imu.csv:2: time -1e+11 s (key imu.time, with time_offset_s) is outside [-1e+10, 1e+10] s"},
      {kImu, "t_s,lat,lon,h,vn,ve,vd\n0.00,46.5,6.6,400,1,2,3\n0.02,46.5,6.6,400,1e9,0,0\n",
       replaced(kManifest, "  height_datum: ellipsoid\n", "  height_datum: ellipsoid\n  velocity: {columns: [vn, ve, vd], frame: NED, unit: m/s}\n"),
       "gnss.csv:3: key gnss: GNSS velocity north = 1e+09 m/s is beyond any vehicle (|value| <= 10000 m/s)"},
      {kImu, "t_s,lat,lon,h,s\n0.00,46.5,6.6,400,1\n0.02,46.5,6.6,400,1e30\n",
       replaced(kManifest, "  height_datum: ellipsoid\n", "  height_datum: ellipsoid\n  sigma: {columns: [s, s], unit: m}\n"),
       "gnss.csv:3: key gnss: GNSS position sigma 1e+30 m is outside [0.0001, 1e+06] m"},
      {kImu, replaced(kGnss, "0.02,46.5,6.6,400", "0.02,46.5,6.6,2e6"), kManifest, "gnss.csv:3: column key gnss.position.height: height 2e+06"},
      // an aiding stream wholly outside the IMU's time span (a time offset or unit gone wrong)
      {kImu, kGnss, std::string(kManifest) + "time_offset_s: {gnss: 10000}\n",
       "gnss.csv: no record of stream gnss lies within the IMU's time span [0, 0.03] s (it spans [10000, 10000.02] s"},
      // ... or around it with none inside: the spans overlapping passed two fixes at -5 s and 30 s
      {kImu, "t_s,lat,lon,h\n-5,46.5,6.6,400\n30,46.5,6.6,400\n", kManifest,
       "gnss.csv: no record of stream gnss lies within the IMU's time span [0, 0.03] s (it spans [-5, 30] s"},
      // a unit in the header that the manifest contradicts was read in the manifest's (deg/s taken as rad/s: 57x)
      {replaced(kImu, "gx,", "gx[deg/s],"), kGnss, kManifest,
       "imu.csv:1: column 'gx' is in deg/s by its header, but imu.gyro.unit says rad/s: correct the header or the manifest"},
      {replaced(kImu, "t_s,", "t_s[ms],"), kGnss, kManifest, "imu.csv:1: column 't_s' is in ms by its header, but imu.time.unit says s"},
      // one column named twice (also as "gx" and "gx[rad/s]": that read the time column as gy, or crashed)
      {replaced(kImu, "gx,", "gx[rad/s],"), kGnss, replaced(kManifest, "[gx, gy, gz]", "[gx, \"gx[rad/s]\", gz]"),
       "imu.csv:1: keys imu.gyro.columns[0] and imu.gyro.columns[1] name the same column 'gx[rad/s]'"},
      {"idx,t_s,gx[rad/s],gy,gz,ax,ay,az\n1,0.00,0.1,0.2,0.3,0.1,0.2,9.8\n2,0.01,0.1,0.2,0.3,0.1,0.2,9.8\n", kGnss, replaced(kManifest, "[gx, gy, gz]", "[gx, \"gx[rad/s]\", gz]"),
       "imu.csv:1: keys imu.gyro.columns[0] and imu.gyro.columns[1] name the same column"},
      {kImu, kGnss, replaced(kManifest, "[ax, ay, az]", "[ax, ay, gz]"),
       "imu.csv:1: keys imu.gyro.columns[2] and imu.acc.columns[2] name the same column 'gz'"},
      // a time unit 1000x off: an IMU rate outside [1, 1e4] Hz, GNSS fixes faster than any receiver
      {kImu, kGnss, replaced(kManifest, "{column: t_s, unit: s}", "{column: t_s, unit: ms}"),
       "imu.csv:2: the time column 't_s' gives a rate of 100000 Hz, outside [1, 10000] Hz (is imu.time.unit right?)"},
      {kImu, kGnss, replaced(kManifest, "  file: gnss.csv\n  time: {column: t_s, unit: s}", "  file: gnss.csv\n  time: {column: t_s, unit: ms}"),
       "gnss.csv:2: the GNSS fixes come every 2e-05 s (median), faster than the 100 Hz of any receiver (is gnss.time.unit right?)"},
  };
  for (const auto& c : cases) {
    const std::string e = importError(c.manifest, c.imu, c.gnss);
    EXPECT_NE(e.find(c.expect), std::string::npos) << "expected '" << c.expect << "' in: " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

// The barometer's heights and the reference's attitude angles have ranges too:
// a height of 1e12 m replayed to a vertical RMS of 1.1e8 m with exit 0; a pitch
// of 120 deg is not an attitude (roll and yaw wrap, pitch does not).
TEST(ImportManifest, BaroHeightsAndReferenceAnglesOutsideTheirRanges) {
  const std::string baro = "t_s,h\n0.00,400\n0.02,1e12\n";
  const std::string ref = "t_s,lat,lon,h,r,p,y\n0.00,46.5,6.6,400,10,5,350\n0.02,46.5,6.6,400,-170,120,-20\n";
  const std::string streams = "baro:\n  file: baro.csv\n  time: {column: t_s, unit: s}\n  height: {column: h, unit: m}\n"
                              "reference:\n  file: ref.csv\n  time: {column: t_s, unit: s}\n"
                              "  position: {lat: lat, lon: lon, height: h, angle_unit: deg}\n"
                              "  attitude: {roll: r, pitch: p, yaw: y, unit: deg}\n";
  auto error = [&](const std::string& b, const std::string& r) {
    const fs::path dir = test::tempDir();
    writeFile(dir / "m.yaml", std::string(kManifest) + streams);
    writeFile(dir / "imu.csv", kImu);
    writeFile(dir / "gnss.csv", kGnss);
    writeFile(dir / "baro.csv", b);
    writeFile(dir / "ref.csv", r);
    try {
      import::importManifest((dir / "m.yaml").string());
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  const std::string okBaro = replaced(baro, "1e12", "401"), okRef = replaced(ref, ",120,", ",-89.9,");
  EXPECT_EQ(error(okBaro, okRef), "(no error)");
  std::string e = error(baro, okRef);
  EXPECT_NE(e.find("baro.csv:3: key baro: barometric height 1e+12 m is outside [-12000, 1e+06] m"), std::string::npos) << e;
  e = error(okBaro, ref);
  EXPECT_NE(e.find("ref.csv:3: column key reference.attitude.pitch: 120 is outside [-90, 90] deg"), std::string::npos) << e;
  e = error(okBaro, replaced(ref, "-170,", "1e9,"));
  EXPECT_NE(e.find("ref.csv:3: column key reference.attitude.roll: 1e+09 is outside [-360, 360] deg"), std::string::npos) << e;
}

TEST(ImportManifest, IncrementsAreDividedByTheirOwnInterval) {
  // irregular steps: a rate of 1 rad/s as increments over 0.01 and 0.02 s
  const std::string imu = "t_s,gx,gy,gz,ax,ay,az\n0.00,0.01,0,0,0,0,0.098\n0.01,0.01,0,0,0,0,0.098\n0.03,0.02,0,0,0,0,0.196\n";
  const fs::path dir = test::tempDir();
  writeFile(dir / "imu.csv", imu);
  writeFile(dir / "m.yaml", replaced(replaced(replaced(std::string(kManifest).substr(0, std::string(kManifest).find("gnss:")),
                                                      "unit: rad/s", "increments: rad"),
                                             "unit: m/s2", "increments: m/s"),
                                    "axes:", "max_gap_s: 0.05\n  axes:"));
  const Recording d = import::importManifest((dir / "m.yaml").string());
  ASSERT_EQ(d.imu.size(), 3u);
  for (std::size_t k = 1; k < 3; ++k) {
    EXPECT_NEAR(d.imu[k].w_IB_B[0], 1.0, 1e-12);
    EXPECT_NEAR(d.imu[k].f_B[2], 9.8, 1e-12);
  }
  // the first sample's interval is the nominal step: of steps 0.01 and 0.02 s the
  // median is 0.02 s, their mean 0.015 s is more than 1 % away (nominalStep)
  EXPECT_NEAR(d.imu[0].w_IB_B[0], 0.01 / 0.015, 1e-12);
  EXPECT_NEAR(d.imu_rate_hz, 1.0 / 0.015, 1e-9);
}

TEST(ImportManifest, ALongRecordIsStreamedNotReadWhole) {
  // 1.1e6 rows at 200 Hz (1.5 h), ~68 MB of text: more than a whole-file read
  // would hold (64 MiB); the rows come back in order with their values.
  const std::size_t n = 1100000;
  const fs::path dir = test::tempDir();
  {
    std::FILE* f = std::fopen((dir / "imu.csv").c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("t_s,gx,gy,gz,ax,ay,az\n", f);
    for (std::size_t k = 0; k < n; ++k)
      std::fprintf(f, "%.3f,%.9f,-0.000012345,0.000023456,0.012345678,-0.023456789,9.806650000\n", k * 0.005,
                   1e-3 * static_cast<double>(k % 1000));
    std::fclose(f);
  }
  ASSERT_GT(fs::file_size(dir / "imu.csv"), std::uintmax_t(64) << 20);
  writeFile(dir / "m.yaml", std::string(kManifest).substr(0, std::string(kManifest).find("gnss:")));
  const Recording d = import::importManifest((dir / "m.yaml").string());
  ASSERT_EQ(d.imu.size(), n);
  EXPECT_NEAR(d.imu[n - 1].t - d.imu[0].t, (n - 1) * 0.005, 1e-6);
  EXPECT_NEAR(std::abs(d.imu[n - 1].w_IB_B.cwiseAbs().maxCoeff()), 0.999, 1e-9);
}

}  // namespace
// time_zero_unix_s is read as written: its fraction is not a double's
// neighbour of 1.4e9 s, which holds 0.917 only to 2.4e-7 s (a probe saw every
// time one 100 ns tick late after the rawlog's rounding).
TEST(ImportManifest, TimeZeroKeepsItsFractionExactly) {
  const fs::path dir = test::tempDir();
  writeFile(dir / "m.yaml", std::string(kManifest) + "time_zero_unix_s: 1448546404.917\n");
  writeFile(dir / "imu.csv", kImu);
  writeFile(dir / "gnss.csv", kGnss);
  const Recording d = import::importManifest((dir / "m.yaml").string());
  EXPECT_EQ(d.start_unix_s, 1448546404);
  const Recording plain = [&] {
    writeFile(dir / "m.yaml", kManifest);
    return import::importManifest((dir / "m.yaml").string());
  }();
  ASSERT_EQ(d.imu.size(), plain.imu.size());
  for (std::size_t k = 0; k < d.imu.size(); ++k) EXPECT_NEAR(d.imu[k].t, 0.917 + plain.imu[k].t, 1e-12) << k;
}

}  // namespace navimpact
