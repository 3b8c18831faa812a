// navimpact covariance: covariance analysis of navigation uncertainty per IMU
// error model in static conditions (paper Figures 5 and 6).
//   navimpact covariance --config config/paper/covariance_static.yaml --out DIR [--trajectory CSV]
#include <cstdio>
#include <memory>

#include "cli_common.hpp"
#include "navimpact/analysis/covariance_study.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/report/covariance_report.hpp"

namespace {

struct Opts {
  std::string config;
  std::string out;
  bool print_states = false;
  std::string trajectory;
  bool overwrite = false;
  bool allow_large = false;
};

navimpact::cli::Registrar reg({
    "covariance",
    "Covariance analysis: navigation sigma growth per IMU error model, static (paper Figs. 5, 6)",
    [](CLI::App& app) {
      auto o = std::make_shared<Opts>();
      app.add_option("--config", o->config,
                     "study configuration (YAML), e.g. config/paper/covariance_static.yaml")
          ->required();
      app.add_option("--out", o->out, "output directory (covariance.csv, summary.json, PNGs)")
          ->required();
      app.add_option("--trajectory", o->trajectory,
                     "propagate along this trajectory CSV (time_s, lat_rad, lon_rad, alt_m, "
                     "roll_rad, pitch_rad, yaw_rad) instead of the static state");
      app.add_flag("--print-states", o->print_states,
                   "print the filter state layout of every model before running");
      app.add_flag("--allow-large", o->allow_large,
                   "run even when the estimated work or result memory is above the documented budget");
      navimpact::cli::addOverwriteFlag(app, o->overwrite);
      return [o]() -> int {
        namespace an = navimpact::analysis;
        navimpact::OutputSet out(o->out, navimpact::cli::overwriteMode(o->overwrite));
        an::CovarianceStudyConfig cfg = an::loadCovarianceStudyConfig(o->config);
        cfg.allow_large = o->allow_large;
        if (o->print_states)
          std::fputs(navimpact::report::covarianceStateLayouts(an::covarianceModels(cfg)).c_str(), stdout);
        int total = 0;
        for (const auto& s : cfg.model_sets) total += static_cast<int>(s.models.size());
        navimpact::cli::Progress bar("covariance", static_cast<std::size_t>(total));
        auto tick = [&bar](int done, int) { bar.update(done); };
        const an::CovarianceStudyResult res =
            o->trajectory.empty() ? an::runCovarianceStudy(cfg, tick)
                                  : an::runCovarianceStudyAlongTrajectory(cfg, o->trajectory, tick);
        bar.finish();
        navimpact::report::writeCovarianceStudy(cfg, res, out);
        out.commit();
        std::fputs(navimpact::report::covarianceSummary(res).c_str(), stdout);
        for (const auto& p : out.finalPaths()) std::printf("wrote %s\n", p.string().c_str());
        return 0;
      };
    }});

}  // namespace
