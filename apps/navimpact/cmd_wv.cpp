// navimpact wv: empirical Haar wavelet variance (and Allan deviation) of an
// IMU recording, with the R gmwm package's 95 % CI.
//   navimpact wv --input FILE [--rate HZ] [--gyro-unit U] [--acc-unit U] [--axes SPEC]
//                [--label IMU] [--robust [--eff E]] [--allan] --out DIR
// Writes DIR/wv.json, DIR/wv.csv, DIR/wv_gyroscope.png, DIR/wv_accelerometer.png.
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "input.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/gmwm/channels.hpp"
#include "navimpact/report/wv_report.hpp"

namespace {

namespace gm = navimpact::gmwm;

struct Opts {
  navimpact::cli::InputOpts in;
  bool robust = false;
  double eff = 0.6;
  bool allan = false;
  std::string out;
  bool overwrite = false;
};

int run(const Opts& o) {
  navimpact::OutputSet outs(o.out, navimpact::cli::overwriteMode(o.overwrite));
  navimpact::cli::InputFormat fmt;
  const navimpact::ImuSeries s = navimpact::cli::loadInput(o.in, &fmt);
  gm::WvOptions wo;
  wo.robust = o.robust;
  wo.eff = o.eff;
  const gm::RecordingWv w = gm::recordingWv(s, wo, o.allan);

  nlohmann::ordered_json input = {{"file", o.in.input},
                                        {"format", fmt == navimpact::cli::InputFormat::Rawlog ? "rawlog" : "csv"},
                                        {"rate_hz", s.rate_hz},
                                        {"samples", s.size()},
                                        {"units", navimpact::cli::inputUnitsNote(o.in, fmt)}};
  const nlohmann::json selection = navimpact::cli::inputSelectionJson(o.in, s);  // (items() of a temporary dangles)
  for (const auto& [k, v] : selection.items()) input[k] = v;
  navimpact::report::writeWvOutputs(w, input.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), outs);
  outs.commit();

  std::cout << navimpact::report::wvSummary(w) << "wrote";
  for (const auto& p : outs.finalPaths()) std::cout << " " << p.string();
  std::cout << "\n";
  return 0;
}

navimpact::cli::Registrar reg({"wv",
                               "Empirical Haar wavelet variance (and Allan deviation) of an IMU "
                               "recording, with 95 % confidence intervals",
                               [](CLI::App& app) {
                                 auto o = std::make_shared<Opts>();
                                 navimpact::cli::addInputOptions(app, o->in);
                                 auto* robust = app.add_flag("--robust", o->robust,
                                              "robust WV (Tukey biweight M-estimator of scale)");
                                 app.add_option("--eff", o->eff,
                                                "--robust: efficiency of the robust estimator at the Gaussian, in [0.05, 0.99998]")
                                     ->capture_default_str()
                                     ->check(navimpact::cli::robustEfficiency())
                                     ->needs(robust);
                                 app.add_flag("--allan", o->allan,
                                              "also write overlapping Allan deviations");
                                 app.add_option("--out", o->out, "output directory")->required();
                                 navimpact::cli::addOverwriteFlag(app, o->overwrite);
                                 return [o]() -> int { return run(*o); };
                               }});

}  // namespace
