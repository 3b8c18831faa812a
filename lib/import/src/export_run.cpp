#include "navimpact/import/export_run.hpp"

#include <yaml-cpp/yaml.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/core/yaml_load.hpp"

namespace navimpact::import {

namespace {

namespace fs = std::filesystem;
using units::kDeg;

/// Shortest text that reads back to the same double.
void put(std::string& s, double x) {
  char b[32];
  for (int p = 15; p <= 17; ++p) {
    std::snprintf(b, sizeof b, "%.*g", p, x);
    if (std::strtod(b, nullptr) == x) break;
  }
  s += b;
}

void writeText(const fs::path& p, const std::string& s, bool gz) {
  if (gz) {
    gzFile f = gzopen(p.c_str(), "wb6");
    if (!f) throw Error(p.string() + ": cannot open for writing");
    const bool ok = gzwrite(f, s.data(), static_cast<unsigned>(s.size())) == static_cast<int>(s.size());
    if (gzclose(f) != Z_OK || !ok) throw Error(p.string() + ": write failed");
    return;
  }
  std::ofstream out(p, std::ios::binary);
  out << s;
  if (!out) throw Error(p.string() + ": write failed");
}

}  // namespace

std::vector<std::string> exportRun(const Recording& d, const fs::path& dir) {
  if (d.imu.empty()) throw Error(d.source + ": no IMU data to export");
  std::vector<std::string> notes;
  std::ostringstream m;
  m << "# Written by navimpact export from " << d.source << ": SI units, body FRD axes, NED velocities,\n"
    << "# ellipsoidal heights; t_s on the recording's time axis.\n";

  std::string s = "t_s,gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n";
  s.reserve(d.imu.size() * 140);
  for (const auto& r : d.imu) {
    put(s, r.t);
    for (int i = 0; i < 3; ++i) s += ',', put(s, r.w_IB_B[i]);
    for (int i = 0; i < 3; ++i) s += ',', put(s, r.f_B[i]);
    s += '\n';
  }
  writeText(dir / "imu.csv.gz", s, true);
  // a gap rule that accepts the recording as it is: 1.5 x its largest step
  double maxStep = 0.0;
  for (std::size_t k = 1; k < d.imu.size(); ++k) maxStep = std::max(maxStep, d.imu[k].t - d.imu[k - 1].t);
  char gap[64];
  std::snprintf(gap, sizeof gap, "%.9g", 1.5 * maxStep);
  m << "imu:\n  file: imu.csv.gz\n  time: {column: t_s, unit: s}\n"
    << "  gyro: {columns: [gyro_x, gyro_y, gyro_z], unit: rad/s}\n"
    << "  acc: {columns: [acc_x, acc_y, acc_z], unit: m/s2}\n  axes: [x, y, z]\n  max_gap_s: " << gap << "\n";

  if (!d.gnss.empty()) {
    bool vel = false, cov = true, vcov = true;
    for (const auto& f : d.gnss) {
      vel = vel || f.v_N.has_value();
      cov = cov && f.cov_pos_N.has_value();
      vcov = vcov && (!f.v_N || f.cov_vel_N.has_value());
    }
    vcov = vcov && vel;
    if (!cov) notes.push_back("GNSS: some fixes have no covariance: no sigma written");
    s = "t_s,lat_deg,lon_deg,height_m";
    if (vel) s += ",vn_m_s,ve_m_s,vd_m_s";
    if (cov) s += ",sigma_n_m,sigma_e_m,sigma_d_m";
    if (vcov) s += ",sigma_vn_m_s,sigma_ve_m_s,sigma_vd_m_s";
    s += '\n';
    bool offDiag = false;
    for (const auto& f : d.gnss) {
      put(s, f.t);
      s += ',', put(s, f.pos.lat / kDeg);
      s += ',', put(s, f.pos.lon / kDeg);
      s += ',', put(s, f.pos.h);
      if (vel)
        for (int i = 0; i < 3; ++i) {
          s += ',';
          if (f.v_N) put(s, (*f.v_N)[i]);
        }
      if (cov) {
        for (int i = 0; i < 3; ++i) s += ',', put(s, std::sqrt((*f.cov_pos_N)(i, i)));
        offDiag = offDiag || (f.cov_pos_N->diagonal().asDiagonal().toDenseMatrix() - *f.cov_pos_N).cwiseAbs().maxCoeff() >
                                 1e-9 * f.cov_pos_N->trace();
      }
      if (vcov)
        for (int i = 0; i < 3; ++i) {
          s += ',';
          if (f.v_N) put(s, std::sqrt((*f.cov_vel_N)(i, i)));
          else s += "1";  // no velocity on this row: the sigma is not used
        }
      s += '\n';
    }
    if (offDiag) notes.push_back("GNSS: off-diagonal covariance terms left out (only N, E, D sigmas written)");
    writeText(dir / "gnss.csv", s, false);
    m << "gnss:\n  file: gnss.csv\n  time: {column: t_s, unit: s}\n"
      << "  position: {lat: lat_deg, lon: lon_deg, height: height_m, angle_unit: deg}\n  height_datum: ellipsoid\n";
    if (vel) {
      m << "  velocity: {columns: [vn_m_s, ve_m_s, vd_m_s], frame: NED, unit: m/s";
      if (vcov) m << ", sigma: {columns: [sigma_vn_m_s, sigma_ve_m_s, sigma_vd_m_s], unit: m/s}";
      m << "}\n";
    }
    if (cov) m << "  sigma: {columns: [sigma_n_m, sigma_e_m, sigma_d_m], unit: m}\n";
    if (d.lever_arm_B) {
      s.clear();
      for (int i = 0; i < 3; ++i) s += (i ? ", " : ""), put(s, (*d.lever_arm_B)[i]);
      m << "  lever_arm_m: [" << s << "]\n";
    }
  }

  if (!d.baro.empty()) {
    s = "t_s,height_m\n";
    for (const auto& b : d.baro) put(s, b.t), s += ',', put(s, b.h), s += '\n';
    writeText(dir / "baro.csv", s, false);
    m << "baro:\n  file: baro.csv\n  time: {column: t_s, unit: s}\n  height: {column: height_m, unit: m}\n"
      << "  height_datum: ellipsoid\n";
    std::optional<double> sigma = d.baro.front().sigma_m;
    if (!sigma && !d.metadata.empty()) {  // a rawlog keeps the barometer's sigma in its scenario
      try {
        const YAML::Node b = loadYaml(d.metadata)["navimpact_scenario"]["baro"];
        if (b && b["sigma_m"]) sigma = b["sigma_m"].as<double>();
      } catch (const YAML::Exception&) {
      }
    }
    if (sigma) {
      s.clear();
      put(s, *sigma);
      m << "  sigma_m: " << s << "\n";
    }
  }

  if (!d.reference.empty()) {
    const auto& r0 = d.reference.front();
    const bool att = r0.q_BtoN.has_value(), vel = r0.v_N.has_value(), sig = r0.sigma_p_L.has_value();
    for (const auto& r : d.reference)
      if (r.q_BtoN.has_value() != att || r.v_N.has_value() != vel || r.sigma_p_L.has_value() != sig)
        throw Error(d.source + ": reference at t = " + formatNumber(r.t, 10) +
                    " s has other fields than the first one (attitude, velocity, sigma): cannot export it as one CSV");
    s = "t_s,lat_deg,lon_deg,height_m";
    if (att) s += ",roll_deg,pitch_deg,yaw_deg";
    if (vel) s += ",vn_m_s,ve_m_s,vd_m_s";
    if (sig) s += ",sigma_n_m,sigma_e_m,sigma_d_m";
    s += '\n';
    for (const auto& r : d.reference) {
      const earth::Geodetic p = earth::nedToGeodetic(d.origin, r.p_L);
      put(s, r.t);
      s += ',', put(s, p.lat / kDeg);
      s += ',', put(s, p.lon / kDeg);
      s += ',', put(s, p.h);
      if (att) {  // ZYX: C_BtoN = R3(yaw) R2(pitch) R1(roll)
        const Eigen::Matrix3d C = r.q_BtoN->toRotationMatrix();
        s += ',', put(s, std::atan2(C(2, 1), C(2, 2)) / kDeg);
        s += ',', put(s, -std::asin(std::clamp(C(2, 0), -1.0, 1.0)) / kDeg);
        s += ',', put(s, std::atan2(C(1, 0), C(0, 0)) / kDeg);
      }
      if (vel)
        for (int i = 0; i < 3; ++i) s += ',', put(s, (*r.v_N)[i]);
      if (sig)
        for (int i = 0; i < 3; ++i) s += ',', put(s, (*r.sigma_p_L)[i]);
      s += '\n';
    }
    writeText(dir / "reference.csv.gz", s, true);
    m << "reference:\n  file: reference.csv.gz\n  time: {column: t_s, unit: s}\n"
      << "  position: {lat: lat_deg, lon: lon_deg, height: height_m, angle_unit: deg}\n  height_datum: ellipsoid\n";
    if (att) m << "  attitude: {roll: roll_deg, pitch: pitch_deg, yaw: yaw_deg, unit: deg}\n";
    if (vel) m << "  velocity: {columns: [vn_m_s, ve_m_s, vd_m_s], frame: NED, unit: m/s}\n";
    if (sig) m << "  sigma: {columns: [sigma_n_m, sigma_e_m, sigma_d_m], unit: m}\n";
  }
  s.clear();
  put(s, d.origin.lat / kDeg), s += ", lon_deg: ", put(s, d.origin.lon / kDeg), s += ", height_m: ", put(s, d.origin.h);
  m << "origin: {lat_deg: " << s << "}   # of the reference's tangent frame (ellipsoidal height)\n";
  if (d.start_unix_s != 0 || d.t_start_s != 0.0) {
    s.clear();
    put(s, static_cast<double>(d.start_unix_s) - d.t_start_s);
    m << "time_zero_unix_s: " << s << "\n";
  }
  if (!d.metadata.empty()) notes.push_back("the recording's metadata (e.g. an emulation's IMU model) is not exported");
  writeText(dir / "manifest.yaml", m.str(), false);
  return notes;
}

}  // namespace navimpact::import
