// Streaming rawlog -> ImuSeries (MRPT 2.5 serialization; rawlog format as
// written by MRPT's CRawlog / rawlog-grabber).
#include "navimpact/rawlog/imu_reader.hpp"

#include <algorithm>
#include <cmath>
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

#include "mrpt_errors.hpp"
#include "navimpact/core/error.hpp"

namespace navimpact::rawlog {

namespace {

std::string fmtTime(double t) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(6) << t;
  return os.str();
}

struct Sample {
  double t;
  std::size_t entry;
  double v[6];
};

void openOrThrow(mrpt::io::CFileGZInputStream& f, const std::string& path) {
  if (!std::filesystem::exists(path)) throw Error(path + ": file not found");
  bool ok = false;
  try {
    ok = f.open(path);
  } catch (const std::exception& e) {
    throw Error(path + ": cannot open rawlog (" + detail::mrptCause(e) + ")");
  }
  if (!ok) throw Error(path + ": cannot open rawlog");
}

}  // namespace

ImuSeries readImuRawlog(const std::string& path, const std::string& label) {
  InputScope scope(path);
  mrpt::obs::registerAllClasses_mrpt_obs();
  mrpt::io::CFileGZInputStream f;
  openOrThrow(f, path);
  auto arch = mrpt::serialization::archiveFrom(f);

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
        throw Error(path + ": entry " + std::to_string(entry) + " (t = " + fmtTime(s.t) +
                    " s): CObservationIMU '" + label + "' has no " + names[k] + " value");
      s.v[k] = imu->rawMeasurements[idx[k]];
      if (!std::isfinite(s.v[k]))
        throw Error(path + ": entry " + std::to_string(entry) + " (t = " + fmtTime(s.t) + " s): " +
                    names[k] + " is not finite");
    }
    samples.push_back(s);
  };

  for (;; ++entry) {
    mrpt::serialization::CSerializable::Ptr obj;
    try {
      obj = arch.ReadObject();
    } catch (const mrpt::serialization::CExceptionEOF&) {
      break;  // clean end of file, between two objects
    } catch (const std::exception& e) {
      throw Error(path + ": entry " + std::to_string(entry) +
                  ": truncated or malformed rawlog object (" + detail::mrptCause(e) + ")");
    }
    if (!obj) continue;
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
                  fmtTime(samples[i].t) + " s does not increase (previous " +
                  fmtTime(samples[i - 1].t) + " s at entry " +
                  std::to_string(samples[i - 1].entry) + ")");
  }
  std::vector<double> sorted = dt;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double med = sorted[sorted.size() / 2];
  for (std::size_t i = 0; i < dt.size(); ++i) {
    if (std::fabs(dt[i] - med) > 0.01 * med) {
      std::ostringstream os;
      os << path << ": entry " << samples[i + 1].entry << ": IMU time step " << dt[i]
         << " s at t = " << fmtTime(samples[i + 1].t) << " s differs from the median step " << med
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
  mrpt::io::CFileGZInputStream f;
  openOrThrow(f, path);
  unsigned char b = 0;
  if (f.Read(&b, 1) != 1) return false;  // empty: not a rawlog (the CSV reader reports it)
  // Serialized MRPT objects start with a header byte >= 0x80; CSV starts with text.
  return b >= 0x80 || (b < 0x20 && b != '\t' && b != '\n' && b != '\r');
}

}  // namespace navimpact::rawlog
