#include "fuzz_targets.hpp"

#include <new>
#include <stdexcept>

#include "navimpact/analysis/covariance_study.hpp"
#include "navimpact/analysis/replay.hpp"
#include "navimpact/analysis/study.hpp"
#include "navimpact/analysis/sweep.hpp"
#include "navimpact/core/alloc_limit.hpp"
#include "navimpact/core/csv_reader.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/emulation/scenario.hpp"
#include "navimpact/emulation/trajectory.hpp"
#include "navimpact/import/csv_columns.hpp"
#include "navimpact/import/manifest.hpp"
#include "navimpact/rawlog/imu_reader.hpp"
#include "navimpact/rawlog/writer.hpp"
#include "navimpact/core/text_io.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/stochastic/model_text.hpp"

namespace navimpact::fuzz {

const std::vector<Target>& targets() {
  static const std::vector<Target> t = {
      {"imu_csv", ".csv",
       [](const std::string& p) {
         CsvImuOptions o;
         o.rate_hz = 100.0;
         o.gyro_unit = "deg/s";
         o.acc_unit = "g";
         (void)readImuCsv(p, o);
       }},
      {"trajectory_csv", ".csv",
       [](const std::string& p) {
         emulation::TrajectorySpec s;
         s.file = p;
         (void)emulation::readTrajectoryCsv(s);
       }},
      {"model_text", ".txt",
       [](const std::string& p) {
         // The one text form of a model: a structure spec and a model string.
         // A model that parses must survive its own text form exactly
         // (formatTerms with 17 digits round-trips by contract).
         const std::string text = readFileMaybeGz(p, std::size_t(1) << 20);
         try {
           (void)stochastic::formatStructure(stochastic::parseStructure(text));
         } catch (const Error&) {
         }
         const auto terms = stochastic::parseTerms(text, 200.0);
         const std::string once = stochastic::formatTerms(terms, 17);
         const std::string twice = stochastic::formatTerms(stochastic::parseTerms(once, 200.0), 17);
         if (once != twice) throw std::logic_error("model text does not round-trip: '" + once + "' -> '" + twice + "'");
         (void)stochastic::formatTerms(terms);
       }},
      {"model_file", ".yaml",
       [](const std::string& p) {
         for (const auto& name : stochastic::listModels(p)) (void)stochastic::loadImuModel(p + ":" + name);
         if (stochastic::listModels(p).empty()) (void)stochastic::loadImuModel(p);
       }},
      {"covariance_config", ".yaml", [](const std::string& p) { (void)analysis::loadCovarianceStudyConfig(p); }},
      {"replay_config", ".yaml", [](const std::string& p) { (void)analysis::loadReplayConfig(p); }},
      {"emulation_config", ".yaml", [](const std::string& p) { (void)emulation::loadEmulationConfig(p); }},
      {"study_config", ".yaml", [](const std::string& p) { (void)analysis::loadStudyConfig(p); }},
      {"sweep_config", ".yaml", [](const std::string& p) { (void)analysis::loadSweepConfig(p); }},
      {"imu_rawlog", ".rawlog",
       [](const std::string& p) {
         try {
           (void)rawlog::readImuRawlog(p, "IMU");  // navimpact's label
         } catch (const Error& e) {
           if (std::string(e.what()).find("no CObservationIMU with label 'IMU'") == std::string::npos) throw;
           (void)rawlog::readImuRawlog(p, "XSENS");  // the label of the MRPT sample seed
         }
       }},
      {"rawlog", ".rawlog", [](const std::string& p) { (void)rawlog::readRawlog(p); }},
      // navimpact import: the manifest (its streams: tests/fuzz/import_run, the
      // first 7 s of the Katwijk run) and the CSV column reader of its streams.
      {"import_manifest", ".yaml", [](const std::string& p) { (void)import::importManifest(p); }},
      {"import_csv", ".csv",
       [](const std::string& p) {
         try {  // an IMU stream, else a GNSS stream with per-fix sigmas that may be empty
           (void)import::readColumns(p, {{"t_s", "imu.time.column"},
                                         {"gyro_x", "imu.gyro.columns[0]"},
                                         {"acc_z", "imu.acc.columns[2]"}});
         } catch (const Error& e) {
           if (std::string(e.what()).find("no column 'gyro_x'") == std::string::npos) throw;
           (void)import::readColumns(p, {{"t_s", "gnss.time.column"},
                                         {"lat_deg", "gnss.position.lat"},
                                         {"std_n_m", "gnss.sigma.columns[0]", true}});
         }
       }},
  };
  return t;
}

std::filesystem::path mirrorSourceLayout(const std::filesystem::path& dir, const std::filesystem::path& src) {
  const std::filesystem::path root = dir / "root";
  std::filesystem::create_directories(root / "config/case");
  std::filesystem::create_directory_symlink(src / "config/models", root / "config/models");
  std::filesystem::create_directory_symlink(src / "datasets", root / "datasets");
  std::filesystem::create_directory_symlink(src / "tests", root / "tests");
  return root / "config/case";
}

std::string runOne(const Target& t, const std::string& path) {
  constexpr std::size_t kCap = std::size_t(1) << 30;  // no single allocation above 1 GiB
  AllocationLimit::takeRefused();
  try {
    AllocationLimit limit(kCap);
    t.read(path);
    return "";
  } catch (const Error& e) {
    const std::string m = e.what();
    if (m.empty()) throw std::runtime_error("empty error message");
    if (m.find('\n') != std::string::npos) throw std::runtime_error("error message of more than one line: " + m);
    return m;
  } catch (const std::bad_alloc&) {
    const std::size_t n = AllocationLimit::takeRefused();
    throw std::runtime_error(n ? "asked for one allocation of " + std::to_string(n) + " bytes"
                               : "std::bad_alloc (out of memory)");
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("exception other than navimpact::Error: ") + e.what());
  } catch (...) {
    throw std::runtime_error("non-standard exception");
  }
}

}  // namespace navimpact::fuzz
