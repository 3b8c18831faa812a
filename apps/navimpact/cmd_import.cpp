// navimpact import: a measured run (CSV streams described by a YAML manifest) -> MRPT rawlog.
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli_common.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/import/manifest.hpp"
#include "navimpact/rawlog/writer.hpp"

namespace {

struct Opts {
  std::string manifest;
  std::string out;
  bool no_gzip = false;
  int gzip_level = 1;
  bool overwrite = false;
};

navimpact::cli::Registrar reg({
    "import",
    "Import a measured run (IMU, GNSS, baro, reference CSV streams described by a YAML manifest) as an MRPT rawlog",
    [](CLI::App& app) {
      auto o = std::make_shared<Opts>();
      app.add_option("--manifest", o->manifest, "run manifest (YAML; README, 'Import'), e.g. datasets/katwijk_rover/manifest.yaml")
          ->required();
      app.add_option("--out", o->out, "output rawlog (FILE.rawlog; gzip-compressed unless --no-gzip)")->required();
      app.add_flag("--no-gzip", o->no_gzip, "write the rawlog uncompressed");
      app.add_option("--gzip-level", o->gzip_level, "zlib level 1 (fast, default) .. 9 (smallest)")->check(CLI::Range(1, 9));
      navimpact::cli::addOverwriteFlag(app, o->overwrite);
      return [o]() -> int {
        namespace fs = std::filesystem;
        auto outs = navimpact::OutputSet::singleFile(o->out, navimpact::cli::overwriteMode(o->overwrite));
        navimpact::import::ImportReport rep;
        const auto d = navimpact::import::importManifest(o->manifest, &rep);
        const auto staged = outs.stagedFile();
        navimpact::rawlog::RawlogWriteOptions wo;
        wo.gzip = !o->no_gzip;
        wo.gzip_level = o->gzip_level;
        navimpact::rawlog::writeRawlog(staged.string(), d, wo);
        const auto bytes = fs::file_size(staged);
        outs.commit();
        for (const auto& n : d.notices) std::printf("notice: %s\n", n.c_str());
        const double t0 = d.imu.front().t, t1 = d.imu.back().t;
        std::printf("IMU %zu samples, %.3f s at %g Hz (largest step %.4g s) from %s\n", d.imu.size(), t1 - t0,
                    rep.imu_rate_hz, rep.imu_max_gap_s, rep.imu_file.c_str());
        if (!rep.gnss_file.empty())
          std::printf("GNSS %zu fixes (%s, %s) from %s\n", d.gnss.size(),
                      d.gnss.front().v_N ? "with velocity" : "position only",
                      !d.gnss.front().cov_pos_N                               ? "no sigma"
                      : d.gnss.front().v_N && !d.gnss.front().cov_vel_N       ? "with position sigma, velocity without: replay needs noise.sigma_vel_*"
                                                                              : "with sigma",
                      rep.gnss_file.c_str());
        if (!rep.baro_file.empty()) std::printf("BARO %zu samples from %s\n", d.baro.size(), rep.baro_file.c_str());
        if (!rep.reference_file.empty())
          std::printf("reference %zu samples (%s) from %s\n", d.reference.size(),
                      d.reference.front().q_BtoN ? "with attitude" : "position only", rep.reference_file.c_str());
        std::printf("time: t = %.6f .. %.6f s after Unix %lld%s\n", t0, t1, d.start_unix_s,
                    rep.time_base_known ? "" : " (no time_zero_unix_s: the files' own time)");
        std::printf("wrote %s (%.2f MB%s)\n", o->out.c_str(), bytes / 1e6, wo.gzip ? ", gzip" : "");
        return 0;
      };
    }});

}  // namespace
