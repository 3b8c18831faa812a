// navimpact diagnose: what a simulation with today's IMU error model gets wrong
// on a measured static recording, the cause, the extended model and its gain.
//   navimpact diagnose --input STATIC.csv[.gz]|STATIC.rawlog [--rate HZ] [--gyro-unit U]
//                      [--acc-unit U] [--axes SPEC] [--label IMU]
//                      [--time-column NAME] [--start S] [--end S]
//                      --model FILE[:NAME] | fit:SPEC | fit:auto [--robust [--eff E]]  --out DIR
//                      [--trajectory FILE --outage START:DURATION ... [--nav-runs R]]
//                      [--simulations N] [--seed S] [--alpha A] [--threads N]
//   navimpact diagnose --run RUN.rawlog --model FILE[:NAME] [--config REPLAY.yaml] [--static STATIC.csv ...]
//                      [--durations 10,30,60] [--reconverge S] [--realisations N] --out DIR
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "input.hpp"
#include "navimpact/analysis/diagnosis.hpp"
#include "navimpact/analysis/run_diagnosis.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/gmwm/channels.hpp"
#include "navimpact/report/diagnosis_report.hpp"
#include "navimpact/report/run_diagnosis_report.hpp"
#include "navimpact/stochastic/model_file.hpp"

namespace {

/// counts of runs, realisations and folds: [2, 1e6]
const navimpact::limits::Range kCountFrom2{2.0, double(navimpact::limits::kMaxMonteCarloRuns), false, ""};

namespace na = navimpact::analysis;
namespace st = navimpact::stochastic;

struct Opts {
  navimpact::cli::InputOpts in;
  std::string model;
  std::string trajectory;
  std::vector<std::string> outages;
  std::string traj_system = "geodetic";
  int nav_runs = 10;
  std::string out;
  int simulations = 8;
  std::uint64_t seed = 20261121;
  double alpha = 0.01;
  int threads = 0;
  bool overwrite = false;
  bool robust = false;  ///< fit:SPEC: robust GMWM
  double eff = 0.6;
  // --run: a real run (rawlog with a reference) instead of a static recording
  std::string run_rawlog, replay_config, static_file, static_gyro_unit, static_acc_unit, static_axes;
  double static_rate = 0.0;
  std::vector<double> durations{10.0, 30.0, 60.0};
  double reconverge = 30.0;
  int realisations = 50;
  int folds = 5;
  bool allow_large = false;
};

/// `diagnose --run`: predicted against measured outage errors of a real run.
int runOnRun(const Opts& o) {
  na::RunDiagnosisOptions ro;
  if (!o.replay_config.empty()) ro.replay = na::loadReplayConfig(o.replay_config, {"rawlog", "model"});  // --run, --model
  ro.replay.rawlog = o.run_rawlog;
  ro.replay.model_spec = o.model;
  ro.durations_s = o.durations;
  ro.reconverge_s = o.reconverge;
  ro.realisations = o.realisations;
  ro.folds = o.folds;
  ro.allow_large = o.allow_large;
  ro.seed = o.seed;
  ro.alpha = o.alpha;
  ro.threads = o.threads;
  if (!o.static_file.empty()) {
    ro.static_file = o.static_file;
    if (o.static_rate > 0) ro.static_csv.rate_hz = o.static_rate;
    ro.static_csv.gyro_unit = o.static_gyro_unit;
    ro.static_csv.acc_unit = o.static_acc_unit;
    ro.static_csv.axes = o.static_axes;
  }
  if (o.model.rfind("fit:", 0) == 0) throw navimpact::Error("--run needs --model FILE[:NAME] (fit: applies to --input)");
  st::loadImuModel(o.model);  // model problems before the long work
  navimpact::OutputSet out(o.out, navimpact::cli::overwriteMode(o.overwrite));
  navimpact::cli::Progress bar("diagnose --run", 1000);
  ro.progress = [&bar](double f, const std::string&) { bar.update(static_cast<std::size_t>(f * 1000)); };
  const na::RunDiagnosis d = na::diagnoseRun(ro);
  bar.finish();
  nlohmann::json in = {{"run", o.run_rawlog},       {"model", o.model},         {"config", o.replay_config},
                       {"static", o.static_file},   {"durations_s", o.durations}, {"reconverge_s", o.reconverge},
                       {"realisations", o.realisations}, {"folds", o.folds}, {"seed", o.seed},     {"alpha", o.alpha}};
  const std::size_t figs = navimpact::report::writeRunDiagnosisOutputs(
      d, in.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), out);
  out.commit();
  for (const auto& n : d.notices) std::cerr << "navimpact: notice: " << n << "\n";
  std::cout << navimpact::report::runDiagnosisSummary(d);
  std::cout << "wrote " << (std::filesystem::path(o.out) / "run_diagnosis.json").string() << ", report.md, "
            << (d.best >= 0 ? "model_extended.yaml, filter_extended.yaml, " : "") << figs << " figure(s)\n";
  return 0;
}

/// `fit:SPEC`: the options of fitting SPEC to every channel of the data first (GMWM).
navimpact::gmwm::RecordingFitOptions fitOptions(const std::string& spec, const Opts& o) {
  navimpact::gmwm::RecordingFitOptions f;
  f.structure = spec;
  f.robust = o.robust;
  f.eff = o.eff;
  f.intervals = "asymptotic";
  return f;
}

std::vector<navimpact::Outage> checkOutages(const Opts& o) {
  std::vector<navimpact::Outage> w;
  if (!o.outages.empty() && o.trajectory.empty())
    throw navimpact::Error("--outage needs --trajectory (the navigation part runs along it)");
  if (!o.trajectory.empty() && o.outages.empty())
    throw navimpact::Error("--trajectory needs at least one --outage START:DURATION");
  for (const auto& spec : o.outages) w.push_back(navimpact::parseOutage(spec, "--outage"));
  if (!o.trajectory.empty() && !std::filesystem::exists(o.trajectory))
    throw navimpact::Error("--trajectory " + o.trajectory + ": no such file");
  return w;
}

int run(const Opts& o) {
  if (!o.run_rawlog.empty()) return runOnRun(o);
  if (o.in.input.empty()) throw navimpact::Error("diagnose needs --input STATIC (a static recording) or --run RUN.rawlog");
  if (!(o.alpha > 0 && o.alpha < 0.5)) throw navimpact::Error("--alpha must be in (0, 0.5)");
  const auto windows = checkOutages(o);
  // Model file problems are reported before the (long) data read.
  const bool fit = o.model.rfind("fit:", 0) == 0;
  st::ImuModel model;
  if (!fit && o.robust) throw navimpact::Error("--robust applies to --model fit:SPEC (a robust GMWM fit of the data)");
  if (fit) navimpact::gmwm::checkRecordingFitOptions(fitOptions(o.model.substr(4), o));
  else model = st::loadImuModel(o.model);
  navimpact::OutputSet out(o.out, navimpact::cli::overwriteMode(o.overwrite));

  navimpact::cli::InputFormat fmt = navimpact::cli::InputFormat::Csv;
  const navimpact::ImuSeries data = navimpact::cli::loadInput(o.in, &fmt);
  // Navigation plan (trajectory, outages, recording length) before the long work.
  std::shared_ptr<const na::NavGainPlan> plan;
  if (!o.trajectory.empty()) {
    na::NavGainOptions nopt;
    nopt.trajectory.file = o.trajectory;
    nopt.trajectory.system = o.traj_system;
    nopt.outages = windows;
    nopt.runs = o.nav_runs;
    nopt.seed = o.seed;
    nopt.threads = o.threads;
    nopt.allow_large = o.allow_large;
    plan = na::prepareNavGain(nopt, data.rate_hz, data.size());
  }
  na::DiagnoseOptions dopt;
  dopt.simulations = o.simulations;
  dopt.seed = o.seed;
  dopt.alpha = o.alpha;
  dopt.threads = o.threads;
  dopt.allow_large = o.allow_large;
  na::checkDiagnoseOptions(dopt, data.channels.size(), data.size());  // before a fit
  if (fit) {
    model = navimpact::gmwm::fitRecording(data, fitOptions(o.model.substr(4), o)).model;
    model.source = o.model;
  }

  navimpact::cli::Progress bar("diagnose", 1000);
  dopt.progress = [&bar](double f, const std::string&) {
    bar.update(static_cast<std::size_t>(f * 1000));
  };
  na::Diagnosis d = na::diagnose(data, model, dopt);
  bar.finish();
  if (plan) {
    navimpact::cli::Progress nbar("navigation", 1000);
    na::addNavigationGain(d, data, *plan, [&nbar](double f) {
      nbar.update(static_cast<std::size_t>(f * 1000));
    });
    nbar.finish();
  }

  nlohmann::json in = {{"file", o.in.input},
                       {"format", fmt == navimpact::cli::InputFormat::Rawlog ? "rawlog" : "csv"},
                       {"units", navimpact::cli::inputUnitsNote(o.in, fmt)},
                       {"model", o.model},
                       {"model_rate_hz", model.rate_hz},
                       {"gyro_unit", o.in.gyro_unit},
                       {"acc_unit", o.in.acc_unit},
                       {"seed", o.seed},
                       {"simulations", o.simulations},
                       {"alpha", o.alpha}};
  if (fmt == navimpact::cli::InputFormat::Rawlog) in["label"] = o.in.label;
  in.update(navimpact::cli::inputSelectionJson(o.in, data));
  if (o.robust) {
    in["robust"] = true;
    in["eff"] = o.eff;
  }
  if (!o.trajectory.empty()) {
    in["trajectory"] = o.trajectory;
    in["outages"] = o.outages;
    in["nav_runs"] = o.nav_runs;
  }
  const std::string comment = "extended by navimpact diagnose from " + o.in.input + " (model " + o.model +
                              ", seed " + std::to_string(o.seed) + ")";
  const std::size_t figs = navimpact::report::writeDiagnosisOutputs(d, in.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), comment, out);
  out.commit();

  for (const auto& n : d.notices) std::cerr << "navimpact: notice: " << n << "\n";
  std::cout << navimpact::report::diagnosisSummary(d);
  std::cout << "wrote " << (std::filesystem::path(o.out) / "diagnosis.json").string()
            << ", report.md, model_extended.yaml and " << figs << " figure(s)\n";
  return 0;
}

navimpact::cli::Registrar reg(
    {"diagnose",
     "What a simulation with today's IMU error model gets wrong on static data, the cause, "
     "the extended model and its held-out gain",
     [](CLI::App& app) {
       auto o = std::make_shared<Opts>();
       navimpact::cli::addInputOptions(app, o->in);
       app.get_option("--input")->required(false);
       auto* runOpt = app.add_option("--run", o->run_rawlog,
                                     "a real run: rawlog with IMU, GNSS and a reference (GT), e.g. from navimpact "
                                     "import; predicted against measured GNSS-outage errors")
                          ->excludes("--input");
       app.add_option("--config", o->replay_config,
                      "--run: replay configuration (filter, noise, aids, alignment; as navimpact replay --config)")
           ->needs(runOpt);
       app.add_option("--static", o->static_file,
                      "--run: simulate with windows of this static recording (CSV) instead of the model's errors")
           ->needs(runOpt);
       app.add_option("--static-rate", o->static_rate, "--static: sampling rate [Hz] of a CSV without time column")
           ->check(navimpact::cli::within(navimpact::limits::kImuRateHz));
       app.add_option("--static-gyro-unit", o->static_gyro_unit, "--static: gyroscope unit")
           ->check(navimpact::cli::knownUnit(navimpact::units::Quantity::AngularRate));
       app.add_option("--static-acc-unit", o->static_acc_unit, "--static: accelerometer unit")
           ->check(navimpact::cli::knownUnit(navimpact::units::Quantity::SpecificForce));
       app.add_option("--static-axes", o->static_axes, "--static: sensor-to-body FRD axes");
       app.add_option("--durations", o->durations, "--run: outage durations [s], comma separated")
           ->delimiter(',')
           ->check(navimpact::cli::within(navimpact::limits::kDurationS))
           ->capture_default_str();
       app.add_option("--reconverge", o->reconverge, "--run: GNSS time before each outage [s]")
           ->capture_default_str()
           ->check(navimpact::cli::within(navimpact::limits::kDurationS));
       app.add_option("--realisations", o->realisations, "--run: simulated realisations (seeded by --seed)")
           ->capture_default_str()
           ->check(navimpact::cli::within(kCountFrom2));
       app.add_option("--folds", o->folds,
                      "--run: cross-validation folds (time blocks of the run) for the causes; at most one per outage")
           ->capture_default_str()
           ->check(navimpact::cli::within(kCountFrom2));
       app.add_flag("--allow-large", o->allow_large,
                    "run even when the estimated work or memory of the simulations or navigation runs is above the "
                    "documented budget");
       app.add_option("--model", o->model,
                      "model simulated today: FILE[:NAME], or fit:SPEC (e.g. fit:WN+GM) to fit "
                      "that structure to the data first, or fit:auto (the structure chosen by the WIC "
                      "per channel, as fit --structure auto)")
           ->required();
       auto* robust = app.add_flag("--robust", o->robust,
                                   "with fit:SPEC: robust GMWM (fit the robust WV, Tukey biweight)");
       app.add_option("--eff", o->eff, "--robust: efficiency of the robust WV at the Gaussian, in [0.05, 0.99998]")
           ->capture_default_str()
           ->check(navimpact::cli::robustEfficiency())
           ->needs(robust);
       app.add_option("--trajectory", o->trajectory,
                      "trajectory CSV for the navigation gain (columns time_s, lat_rad, lon_rad, "
                      "alt_m, roll_rad, pitch_rad, yaw_rad as datasets/uav_flight_260s.csv.gz)");
       app.add_option("--trajectory-system", o->traj_system,
                      "trajectory coordinates: geodetic (lat/lon/height columns)")
           ->check(CLI::IsMember({"geodetic"}))
           ->capture_default_str();
       app.add_option("--outage", o->outages,
                      "GNSS outage START:DURATION [s from the trajectory start] (repeatable)")
           ->check(navimpact::cli::parsedBy([](const std::string& s) { navimpact::parseOutage(s, "--outage"); },
                                            "START:DURATION"));
       app.add_option("--nav-runs", o->nav_runs,
                      "paired navigation runs (recording windows x GNSS/baro noise), >= 2")
           ->capture_default_str()
           ->check(navimpact::cli::within(kCountFrom2));
       app.add_option("--out", o->out, "output directory")->required();
       navimpact::cli::addOverwriteFlag(app, o->overwrite);
       app.add_option("--simulations", o->simulations, "Monte-Carlo simulations per channel (0, or 2 and more)")
           ->capture_default_str()
           ->check(navimpact::cli::within({0.0, double(navimpact::limits::kMaxMonteCarloRuns), false, ""}))
           ->check(navimpact::cli::zeroOrAtLeast(2.0, "one simulation has no spread"));
       app.add_option("--seed", o->seed, "root seed")->capture_default_str()->check(navimpact::cli::seedValue());
       app.add_option("--alpha", o->alpha, "family-wise level for the whole record")
           ->capture_default_str()
           ->check(navimpact::cli::within(navimpact::cli::kAlpha, true));
       app.add_option("--threads", o->threads, "worker threads (0 = all cores)")
           ->check(navimpact::cli::within(navimpact::cli::kThreads));
       // a flag of the other mode was ignored without a word (diagnose --run
       // --outage 100:10 --end 50 gave the run's result, exit 0)
       for (const char* name : {"--rate", "--gyro-unit", "--acc-unit", "--axes", "--label", "--time-column", "--time-unit",
                                "--start", "--end", "--robust", "--eff", "--trajectory", "--trajectory-system", "--outage",
                                "--nav-runs", "--simulations"})
         app.get_option(name)->excludes(runOpt);
       for (const char* name : {"--durations", "--reconverge", "--realisations", "--folds"}) app.get_option(name)->needs(runOpt);
       for (const char* name : {"--static-rate", "--static-gyro-unit", "--static-acc-unit", "--static-axes"})
         app.get_option(name)->needs("--static");
       return [o]() { return run(*o); };
     }});

}  // namespace
