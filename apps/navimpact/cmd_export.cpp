// navimpact export: a rawlog as CSV streams plus the manifest that imports them again.
#include <cstdio>
#include <memory>

#include "cli_common.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/import/export_run.hpp"
#include "navimpact/rawlog/writer.hpp"

namespace {

struct Opts {
  std::string rawlog;
  std::string out;
  std::string imu_label, gnss_label;
  bool overwrite = false;
};

navimpact::cli::Registrar reg({
    "export",
    "Write a rawlog's streams as CSV files (SI, body FRD, NED) with the manifest that 'navimpact import' reads back",
    [](CLI::App& app) {
      auto o = std::make_shared<Opts>();
      app.add_option("--rawlog", o->rawlog, "input rawlog (labels IMU, GNSS, BARO, GT as navimpact writes them)")->required();
      app.add_option("--out", o->out, "output folder: imu.csv.gz, gnss.csv, baro.csv, reference.csv, manifest.yaml")->required();
      app.add_option("--imu-label", o->imu_label, "IMU label of a rawlog navimpact did not write (default: the only one)");
      app.add_option("--gnss-label", o->gnss_label, "GNSS label of a rawlog navimpact did not write (default: the only one)");
      navimpact::cli::addOverwriteFlag(app, o->overwrite);
      return [o]() -> int {
        navimpact::OutputSet outs(o->out, navimpact::cli::overwriteMode(o->overwrite));
        const auto d = navimpact::rawlog::readRawlog(o->rawlog, {o->imu_label, o->gnss_label});
        const auto notes = navimpact::import::exportRun(d, outs.stagingDir());
        outs.commit();
        for (const auto& n : d.notices) std::printf("notice: %s\n", n.c_str());
        for (const auto& n : notes) std::printf("notice: %s\n", n.c_str());
        std::printf("exported IMU %zu, GNSS %zu, BARO %zu, reference %zu records to %s/ (manifest.yaml)\n", d.imu.size(),
                    d.gnss.size(), d.baro.size(), d.reference.size(), o->out.c_str());
        return 0;
      };
    }});

}  // namespace
