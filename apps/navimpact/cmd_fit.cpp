// navimpact fit: GMWM fit of an IMU error model to a static recording.
//   navimpact fit --input FILE [--rate HZ] [--gyro-unit U] [--acc-unit U] [--axes SPEC]
//                 [--label L] [--channels gyro_x,...] --structure SPEC|auto
//                 [--max-gm N] [--bootstrap N] [--intervals profile|asymptotic]
//                 [--weights r|model|efficient] [--robust [--eff E]] [--seed S] --out DIR
// Writes DIR/model.yaml (stochastic::loadImuModel reads it back), DIR/fit.json
// (estimates, intervals, WV and model WV per channel) and one WV figure per
// sensor (fit_gyroscope.png, fit_accelerometer.png), all or nothing.
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "input.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/core/text_io.hpp"
#include "navimpact/gmwm/channels.hpp"
#include "navimpact/report/fit_report.hpp"

namespace {

namespace gm = navimpact::gmwm;

struct Opts {
  navimpact::cli::InputOpts in;  // --input --rate --gyro-unit --acc-unit --axes --label (input.hpp)
  std::string channels;
  gm::RecordingFitOptions fit;   // --structure --max-gm --bootstrap --intervals --weights --seed
  std::string out;
  bool overwrite = false;
};

/// "gyro_x,acc_z" -> {gyro_x, acc_z}; an empty entry ("," or "gyro_x,,acc_z")
/// is an error: "--channels ," fitted every channel without a word.
std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string t;
  while (std::getline(ss, t, ',')) out.push_back(t);
  if (!s.empty() && s.back() == ',') out.emplace_back();
  for (const auto& c : out)
    if (c.empty())
      throw navimpact::Error("'" + navimpact::printable(s, 60) +
                             "' has an empty entry (expected channel names separated by commas, e.g. gyro_x,acc_z)");
  return out;
}

int run(Opts o) {
  o.fit.channels = splitList(o.channels);
  gm::checkRecordingFitOptions(o.fit);  // a bad option fails before reading a large file
  navimpact::OutputSet outs(o.out, navimpact::cli::overwriteMode(o.overwrite));
  navimpact::cli::InputFormat fmt{};
  const navimpact::ImuSeries s = navimpact::cli::loadInput(o.in, &fmt);

  navimpact::cli::Progress prog("fit", o.fit.channels.empty() ? s.channels.size() : o.fit.channels.size());
  const gm::RecordingFit f = gm::fitRecording(s, o.fit, [&prog](std::size_t done, std::size_t) { prog.update(done); });
  prog.finish();

  nlohmann::json input = {{"file", o.in.input},
                                {"format", fmt == navimpact::cli::InputFormat::Rawlog ? "rawlog" : "csv"},
                                {"rate_hz", s.rate_hz},
                                {"samples", s.size()},
                                {"units", navimpact::cli::inputUnitsNote(o.in, fmt)},
                                {"axes", o.in.axes},
                                {"label", o.in.label}};
  input.update(navimpact::cli::inputSelectionJson(o.in, s));
  navimpact::report::writeFitOutputs(f, input.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), NAVIMPACT_VERSION, outs);
  outs.commit();

  std::cout << navimpact::report::fitSummary(f) << "wrote";
  for (const auto& p : outs.finalPaths()) std::cout << " " << p.string();
  std::cout << "\n";
  return 0;
}

navimpact::cli::Registrar reg({
    "fit",
    "GMWM fit of IMU error models (WN, QN, RW, DR, GM, SIN) to a static recording",
    [](CLI::App& app) {
      auto o = std::make_shared<Opts>();
      navimpact::cli::addInputOptions(app, o->in);
      app.add_option("--channels", o->channels, "comma-separated channels to fit (default: all in the file)")
          ->check(navimpact::cli::parsedBy([](const std::string& v) {
            // an empty list fitted every channel, as if the flag were not given
            if (navimpact::trim(v).empty()) throw navimpact::Error("names no channel (leave the flag out to fit all)");
            splitList(v);
          }, "NAMES"));
      app.add_option("--structure", o->fit.structure,
                     "model structure for every channel, e.g. WN+GM+GM+DR, or 'auto' (WIC selection)")
          ->required();
      auto* maxGm = app.add_option("--max-gm", o->fit.max_gm, "auto: largest number of GM terms among the candidates (0..3)")
          ->check(navimpact::cli::within({0.0, 3.0, false, ""}));
      auto* bootstrap = app.add_option("--bootstrap", o->fit.bootstrap,
                                       "parametric bootstrap replicates for the intervals (0: --intervals; else 39 .. 10000)")
          ->check(navimpact::cli::within({0.0, 10000.0, false, ""}))
          ->check(navimpact::cli::zeroOrAtLeast(gm::kMinBootstrap, "a 95 % percentile interval needs (N + 1) * 0.025 >= 1"));
      app.add_flag("--allow-large", o->fit.allow_large,
                   "bootstrap above the simulated-sample budget (README \"Ranges and budgets\")");
      auto* intervals = app.add_option("--intervals", o->fit.intervals,
                     "95 % intervals without --bootstrap: profile (default; follows the objective along "
                     "GM/RW ridges) or asymptotic (delta method)")
          ->check(CLI::IsMember({"profile", "asymptotic"}));
      // --intervals with a bootstrap was ignored without a word (the bootstrap's
      // percentile intervals were written); one of the two, as the help says
      app.parse_complete_callback([o, bootstrap, intervals, maxGm]() {
        if (intervals->count() > 0 && bootstrap->count() > 0 && o->fit.bootstrap > 0)
          throw CLI::ValidationError("--intervals", "applies without --bootstrap (a bootstrap gives its own percentile "
                                                    "intervals); drop one of the two");
        // with a structure given, the candidates' GM count means nothing (it was ignored without a word)
        if (maxGm->count() > 0 && o->fit.structure != "auto")
          throw CLI::ValidationError("--max-gm", "applies to --structure auto (the structure " + o->fit.structure +
                                                     " fixes its GM terms)");
      });
      app.add_option("--weights", o->fit.weights,
                     "GMWM weights: r (default, the R package's 1/(CI_hi-CI_lo)^2), model (iterated "
                     "model-based diagonal) or efficient (inverse of the full WV covariance)")
          ->check(CLI::IsMember({"r", "model", "efficient"}));
      auto* robust = app.add_flag("--robust", o->fit.robust,
                   "robust GMWM: replace isolated spikes, then fit the robust WV (Tukey biweight M-scale, "
                   "Guerrier, Molinari & Victoria-Feser 2014) with its own CI and weights; for records with outliers");
      app.add_option("--eff", o->fit.eff, "--robust: efficiency of the robust WV at the Gaussian, in [0.05, 0.99998]")
          ->capture_default_str()
          ->check(navimpact::cli::robustEfficiency())
          ->needs(robust);
      app.add_option("--seed", o->fit.seed, "seed of the bootstrap")->check(navimpact::cli::seedValue());
      app.add_option("--out", o->out, "output directory (model.yaml, fit.json, fit_*.png)")->required();
      navimpact::cli::addOverwriteFlag(app, o->overwrite);
      return [o]() -> int { return run(*o); };
    }});

}  // namespace
