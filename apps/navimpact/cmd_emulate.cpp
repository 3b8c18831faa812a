// navimpact emulate: trajectory -> perfect IMU -> IMU errors -> GNSS, baro -> MRPT rawlog.
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli_common.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/emulation/scenario.hpp"
#include "navimpact/rawlog/writer.hpp"

namespace {

struct Opts {
  std::string config;
  std::string out;
  bool no_gzip = false;
  bool no_gt = false;
  int gzip_level = 1;
  bool overwrite = false;
};

navimpact::cli::Registrar reg({
    "emulate",
    "Emulate a flight: trajectory CSV -> smooth truth -> perfect IMU + errors, GNSS, baro -> MRPT rawlog",
    [](CLI::App& app) {
      auto o = std::make_shared<Opts>();
      app.add_option("--config", o->config, "emulation configuration (YAML), e.g. config/emulation/uav_flight_260s_ref.yaml")
          ->required();
      app.add_option("--out", o->out, "output rawlog (FILE.rawlog; gzip-compressed unless --no-gzip)")->required();
      app.add_flag("--no-gzip", o->no_gzip, "write the rawlog uncompressed");
      app.add_option("--gzip-level", o->gzip_level,
                     "zlib level 1 (fast, default: compression is most of the write time) .. 9 (smallest)")
          ->check(CLI::Range(1, 9));
      app.add_flag("--no-gt", o->no_gt,
                   "leave out the ground-truth records (label GT), like the rawlog of a real flight");
      navimpact::cli::addOverwriteFlag(app, o->overwrite);
      return [o]() -> int {
        namespace fs = std::filesystem;
        auto outs = navimpact::OutputSet::singleFile(o->out, navimpact::cli::overwriteMode(o->overwrite));
        const navimpact::InputScope scope(o->config);  // names the configuration when the run fails (e.g. out of memory)
        const auto cfg = navimpact::emulation::loadEmulationConfig(o->config);
        auto data = navimpact::emulation::runEmulation(cfg, NAVIMPACT_VERSION);
        if (o->no_gt) {
          data.reference.clear();
          data.notices.push_back("--no-gt: ground-truth records (label GT) left out of the rawlog");
        }
        const auto staged = outs.stagedFile();
        navimpact::rawlog::RawlogWriteOptions wo;
        wo.gzip = !o->no_gzip;
        wo.gzip_level = o->gzip_level;
        navimpact::rawlog::writeRawlog(staged.string(), data, wo);
        const auto bytes = fs::file_size(staged);
        outs.commit();
        for (const auto& n : data.notices) std::printf("notice: %s\n", n.c_str());
        std::printf("emulated %.2f s: IMU %zu samples at %g Hz, GNSS %zu fixes, BARO %zu, GT %zu\n",
                    data.imu.empty() ? 0.0 : data.imu.back().t - data.t_start_s, data.imu.size(),
                    data.imu_rate_hz, data.gnss.size(), data.baro.size(), data.reference.size());
        std::printf("wrote %s (%.2f MB%s)\n", o->out.c_str(), bytes / 1e6, wo.gzip ? ", gzip" : "");
        return 0;
      };
    }});

}  // namespace
