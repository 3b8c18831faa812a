// Streaming rawlog -> ImuSeries (MRPT 2.5 serialization; rawlog format as
// written by MRPT's CRawlog / rawlog-grabber).
#include "navimpact/rawlog/imu_reader.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <map>
#include <mrpt/core/Clock.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/obs/registerAllClasses.h>
#include <mrpt/serialization/CArchive.h>
#include <sstream>
#include <vector>

#include "entry_reader.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"

namespace navimpact::rawlog {

namespace {

struct Sample {
  double t;
  std::size_t entry;
  double v[6];
};

}  // namespace

ImuSeries readImuRawlog(const std::string& path, const std::string& label) {
  InputScope scope(path);
  if (!std::filesystem::exists(path)) throw Error(path + ": file not found");
  detail::EntryReader reader(path);

  std::vector<Sample> samples;
  std::map<std::string, std::size_t> labelsFound;  // "label (Class)" -> count
  std::size_t entry = 0;

  auto handle = [&](const mrpt::obs::CObservation::Ptr& obs) {
    if (!obs) return;
    const auto imu = std::dynamic_pointer_cast<mrpt::obs::CObservationIMU>(obs);
    if (!imu || imu->sensorLabel != label) {
      std::string cls = obs->GetRuntimeClass()->className;
      if (const auto p = cls.rfind("::"); p != std::string::npos) cls = cls.substr(p + 2);
      if (labelsFound.size() < 20) ++labelsFound["'" + printable(obs->sensorLabel, 40) + "' (" + cls + ")"];
      return;
    }
    using namespace mrpt::obs;
    static const TIMUDataIndex idx[6] = {IMU_WX, IMU_WY, IMU_WZ, IMU_X_ACC, IMU_Y_ACC, IMU_Z_ACC};
    static const char* names[6] = {"IMU_WX", "IMU_WY", "IMU_WZ", "IMU_X_ACC", "IMU_Y_ACC", "IMU_Z_ACC"};
    Sample s;
    s.t = mrpt::Clock::toDouble(imu->timestamp);
    s.entry = entry;
    for (int k = 0; k < 6; ++k) {
      if (!imu->has(idx[k]))
        throw Error(path + ": entry " + std::to_string(entry) + " (t = " + formatFixed(s.t, 6) +
                    " s): CObservationIMU '" + label + "' has no " + names[k] + " value");
      s.v[k] = imu->rawMeasurements[idx[k]];
      if (!std::isfinite(s.v[k]))
        throw Error(path + ": entry " + std::to_string(entry) + " (t = " + formatFixed(s.t, 6) + " s): " +
                    names[k] + " is not finite");
      if (std::abs(s.v[k]) > (k < 3 ? kMaxAbsAngularRate : kMaxAbsSpecificForce))
        throw Error(path + ": entry " + std::to_string(entry) + " (t = " + formatFixed(s.t, 6) + " s): " + names[k] +
                    " = " + formatNumber(s.v[k]) + " is beyond any IMU (|value| <= " +
                    (k < 3 ? "1000 rad/s" : "1e5 m/s^2") + ")");
    }
    samples.push_back(s);
  };

  for (;;) {
    const mrpt::serialization::CSerializable::Ptr obj = reader.next();
    if (!obj) break;  // clean end of file, between two objects
    entry = reader.entry();
    if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(obj)) {
      for (const auto& o : *sf) handle(o);
    } else if (auto o = std::dynamic_pointer_cast<mrpt::obs::CObservation>(obj)) {
      handle(o);
    }
    // CActionCollection and any other object: not IMU data, skipped.
  }

  if (samples.empty()) {
    std::string found;
    for (const auto& [k, n] : labelsFound) found += (found.empty() ? "" : ", ") + k;
    if (found.empty()) found = "none";
    throw Error(path + ": no CObservationIMU with label '" + label + "' (labels found: " + found +
                ")");
  }
  if (samples.size() < 2)
    throw Error(path + ": only one CObservationIMU with label '" + label +
                "', cannot derive a sampling rate");

  // Time checks: strictly increasing, uniform within 1 % of the median step.
  std::vector<double> dt(samples.size() - 1);
  for (std::size_t i = 1; i < samples.size(); ++i) {
    dt[i - 1] = samples[i].t - samples[i - 1].t;
    if (!(dt[i - 1] > 0.0))
      throw Error(path + ": entry " + std::to_string(samples[i].entry) + ": IMU timestamp " +
                  formatFixed(samples[i].t, 6) + " s does not increase (previous " +
                  formatFixed(samples[i - 1].t, 6) + " s at entry " +
                  std::to_string(samples[i - 1].entry) + ")");
  }
  std::vector<double> sorted = dt;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double med = sorted[sorted.size() / 2];
  for (std::size_t i = 0; i < dt.size(); ++i) {
    if (std::fabs(dt[i] - med) > 0.01 * med) {
      std::ostringstream os;
      os << path << ": entry " << samples[i + 1].entry << ": IMU time step " << dt[i]
         << " s at t = " << formatFixed(samples[i + 1].t, 6) << " s differs from the median step " << med
         << " s by more than 1 % (gap or jitter; the series must be uniformly sampled)";
      throw Error(os.str());
    }
  }

  ImuSeries s;
  s.source = path;
  s.t0_s = samples.front().t;
  s.rate_hz = static_cast<double>(samples.size() - 1) / (samples.back().t - samples.front().t);
  for (int k = 0; k < 6; ++k) {
    ImuChannel ch;
    ch.name = kChannelNames[k];
    ch.quantity = channelQuantity(ch.name);
    ch.x.resize(samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i) ch.x[i] = samples[i].v[k];
    s.channels.push_back(std::move(ch));
  }
  return s;
}

bool isRawlogFile(const std::string& path) {
  const std::string p = path;
  auto endsWith = [&](const std::string& suf) {
    return p.size() >= suf.size() && p.compare(p.size() - suf.size(), suf.size(), suf) == 0;
  };
  if (endsWith(".rawlog") || endsWith(".rawlog.gz")) return true;
  GzInput f(path);
  unsigned char b[16] = {};
  const std::size_t n = f.read(b, sizeof b);
  if (n == 0) return false;  // empty: not a rawlog (the CSV reader reports it)
  // a packed file (xz, zstd, ...): the CSV reader names it, before any CSV-only flag is weighed
  if (!packedFormat(std::string_view(reinterpret_cast<const char*>(b), n)).empty()) return false;
  // A UTF-8 byte-order mark starts a text (CSV) file.
  if (n >= 3 && b[0] == 0xEF && b[1] == 0xBB && b[2] == 0xBF) return false;
  // So does a UTF-16 one (the CSV reader says it is one).
  if (n >= 2 && ((b[0] == 0xFF && b[1] == 0xFE) || (b[0] == 0xFE && b[1] == 0xFF))) return false;
  // Serialized MRPT objects start with a header byte >= 0x80; CSV starts with text.
  return b[0] >= 0x80 || (b[0] < 0x20 && b[0] != '\t' && b[0] != '\n' && b[0] != '\r');
}

}  // namespace navimpact::rawlog
