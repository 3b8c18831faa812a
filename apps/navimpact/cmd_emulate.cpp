// navimpact emulate: trajectory -> perfect IMU -> IMU errors -> GNSS, baro -> MRPT rawlog.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

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
  bool allow_large = false;
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
      app.add_flag("--allow-large", o->allow_large,
                   "run even when the run is above the documented budget (IMU samples; see README, Ranges and budgets)");
      navimpact::cli::addOverwriteFlag(app, o->overwrite);
      return [o]() -> int {
        namespace fs = std::filesystem;
        auto outs = navimpact::OutputSet::singleFile(o->out, navimpact::cli::overwriteMode(o->overwrite));
        const navimpact::InputScope scope(o->config);  // names the configuration when the run fails (e.g. out of memory)
        auto cfg = navimpact::emulation::loadEmulationConfig(o->config);
        cfg.allow_large = o->allow_large;
        const auto staged = outs.stagedFile();
        navimpact::rawlog::RawlogWriteOptions wo;
        wo.gzip = !o->no_gzip;
        wo.gzip_level = o->gzip_level;
        // the run streams into the rawlog block by block (bounded memory, whatever its duration)
        struct Sink : navimpact::emulation::RecordingSink {
          std::string path;
          navimpact::rawlog::RawlogWriteOptions wo;
          bool no_gt = false;
          std::unique_ptr<navimpact::rawlog::RawlogWriter> w;
          std::vector<std::string> notices;
          double imu_rate_hz = 0.0, t_start = 0.0, t_last = 0.0;
          std::size_t imu = 0, gnss = 0, baro = 0, gt = 0;
          void begin(const navimpact::Recording& h) override {
            notices = h.notices;
            imu_rate_hz = h.imu_rate_hz;
            t_start = h.t_start_s;
            w = std::make_unique<navimpact::rawlog::RawlogWriter>(path, h, wo);
          }
          void append(const navimpact::Recording& b, double until) override {
            imu += b.imu.size();
            gnss += b.gnss.size();
            baro += b.baro.size();
            if (!b.imu.empty()) t_last = b.imu.back().t;
            if (!no_gt) {
              gt += b.reference.size();
              w->append(b, until);
              return;
            }
            navimpact::Recording c;
            c.imu = b.imu;
            c.gnss = b.gnss;
            c.baro = b.baro;
            w->append(c, until);
          }
        } sink;
        sink.path = staged.string();
        sink.wo = wo;
        sink.no_gt = o->no_gt;
        navimpact::emulation::runEmulation(cfg, NAVIMPACT_VERSION, sink);
        sink.w->close();
        if (o->no_gt) sink.notices.push_back("--no-gt: ground-truth records (label GT) left out of the rawlog");
        const auto bytes = fs::file_size(staged);
        outs.commit();
        for (const auto& n : sink.notices) std::printf("notice: %s\n", n.c_str());
        std::printf("emulated %.2f s: IMU %zu samples at %g Hz, GNSS %zu fixes, BARO %zu, GT %zu\n",
                    sink.imu == 0 ? 0.0 : sink.t_last - sink.t_start, sink.imu, sink.imu_rate_hz, sink.gnss,
                    sink.baro, sink.gt);
        std::printf("wrote %s (%.2f MB%s)\n", o->out.c_str(), bytes / 1e6, wo.gzip ? ", gzip" : "");
        return 0;
      };
    }});

}  // namespace
