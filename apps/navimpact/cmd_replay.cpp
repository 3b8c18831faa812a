// navimpact replay: run the EKF over a rawlog (IMU, GNSS, BARO, GT) with GNSS outages injected.
#include <algorithm>
#include <optional>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "navimpact/analysis/replay.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/report/replay_report.hpp"

namespace {

struct Opts {
  std::string rawlog, config, model, out, imu_label, gnss_label;
  std::vector<std::string> outages;
  std::string outages_every;
  std::optional<int> propagate_every;
  double max_imu_gap_s = -1.0;
  bool overwrite = false;
};

navimpact::cli::Registrar reg({
    "replay",
    "Replay a rawlog (labels IMU, GNSS, BARO, GT) through the GNSS/INS EKF with GNSS outages; "
    "writes solution.csv, summary.json and error figures",
    [](CLI::App& app) {
      auto o = std::make_shared<Opts>();
      app.add_option("--rawlog", o->rawlog, "rawlog to replay (default: 'rawlog:' of --config)");
      app.add_option("--config", o->config, "replay configuration (YAML), e.g. config/replay/default.yaml");
      app.add_option("--model", o->model,
                     "IMU error model of the filter, FILE[:NAME] (default: the model recorded in the rawlog)");
      app.add_option("--outage", o->outages,
                     "GNSS outage START:DURATION [s] from the start of the IMU data; repeatable; "
                     "replaces the configuration's outages")
          ->check(navimpact::cli::parsedBy([](const std::string& s) { navimpact::parseOutage(s, "--outage"); },
                                           "START:DURATION"));
      app.add_option("--outages-every", o->outages_every,
                     "GNSS outages all along the run, PERIOD:DURATION [s]: each after PERIOD - DURATION s of "
                     "GNSS from the filter start; added to the other outages")
          ->check(navimpact::cli::parsedBy([](const std::string& s) { navimpact::parseOutagePattern(s); },
                                           "PERIOD:DURATION"));
      app.add_option("--propagate-every", o->propagate_every,
                     "propagate the covariance every k IMU samples (default 10)")
          ->check(CLI::Range(1, navimpact::limits::kMaxPropagateEvery));
      app.add_option("--imu-label", o->imu_label,
                     "IMU label of a rawlog navimpact did not write (default: the only one present)");
      app.add_option("--gnss-label", o->gnss_label,
                     "GNSS label of a rawlog navimpact did not write (default: the only one present)");
      app.add_option("--max-imu-gap", o->max_imu_gap_s,
                     "accept IMU gaps up to S seconds and propagate across them (default 0: a gap is an error)")
          ->check(navimpact::cli::within({0.0, navimpact::analysis::kMaxImuGapS, false, "s"}));
      app.add_option("--out", o->out, "output folder")->required();
      navimpact::cli::addOverwriteFlag(app, o->overwrite);
      return [o]() -> int {
        navimpact::OutputSet out(o->out, navimpact::cli::overwriteMode(o->overwrite));
        navimpact::analysis::ReplayConfig cfg;
        if (!o->config.empty()) {
          std::vector<std::string> flags;  // keys the command line replaces
          if (!o->rawlog.empty()) flags.push_back("rawlog");
          if (!o->model.empty()) flags.push_back("model");
          cfg = navimpact::analysis::loadReplayConfig(o->config, flags);
        }
        if (!o->rawlog.empty()) cfg.rawlog = o->rawlog;
        if (!o->model.empty()) cfg.model_spec = o->model;
        if (!o->imu_label.empty()) cfg.imu_label = o->imu_label;
        if (!o->gnss_label.empty()) cfg.gnss_label = o->gnss_label;
        if (!o->outages.empty()) {
          std::vector<navimpact::Outage> outages;
          std::vector<std::string> names;
          for (const auto& s : o->outages) {
            outages.push_back(navimpact::parseOutage(s, "--outage"));
            names.push_back("--outage " + navimpact::outageText(outages.back()));
          }
          cfg.setOutages(std::move(outages), std::move(names));
        }
        if (!o->outages_every.empty()) cfg.outages_every = navimpact::parseOutagePattern(o->outages_every);
        if (o->propagate_every) cfg.propagate_every = *o->propagate_every;
        if (o->max_imu_gap_s >= 0.0) cfg.max_imu_gap_s = o->max_imu_gap_s;
        // read, filtered and written as it goes (bounded memory, see ReplayWriter)
        navimpact::report::ReplayWriter writer(&out);
        const auto r = navimpact::analysis::runReplay(cfg, writer);
        writer.finish(r);
        out.commit();
        std::fputs(navimpact::report::replaySummary(r).c_str(), stdout);
        // what the folder holds now (the per-outage figures counted, not listed)
        std::vector<std::string> names;
        std::size_t per_outage = 0;
        for (const auto& e : std::filesystem::directory_iterator(o->out)) {
          const std::string n = e.path().filename().string();
          if (n.rfind("errors_outage_", 0) == 0) ++per_outage; else names.push_back(n);
        }
        std::sort(names.begin(), names.end());
        if (per_outage) names.push_back("errors_outage_*.png (" + std::to_string(per_outage) + ")");
        std::string list;
        for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
        std::printf("wrote %s/{%s}\n", o->out.c_str(), list.c_str());
        return 0;
      };
    }});

}  // namespace
