// navimpact diagnose-power: detection power of navimpact diagnose on records
// with hidden effects drawn at random over documented ranges (rate, duration,
// noise level, base model, effect parameters, effect size as a multiple of
// its detection limit), and the false-alarm rate on null records.
//   navimpact diagnose-power --out DIR [--runs N] [--null-runs N] [--snr LO:HI]
//        [--rate LO:HI] [--duration-h LO:HI | --samples LO:HI] [--causes a,b,...]
//        [--seed S] [--alpha A] [--simulations N] [--threads T]
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli_common.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/analysis/diagnose_power.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/report/power_report.hpp"

namespace {

namespace na = navimpact::analysis;
namespace pw = navimpact::analysis::power;

struct Opts {
  std::string out;
  bool overwrite = false;
  int runs = 40, null_runs = 40;
  std::string snr = "0.25:10", rate = "50:1000", duration_h, samples = "65536:262144";
  std::string causes;
  std::uint64_t seed = 20261124;
  double alpha = 0.01;
  int simulations = 4;
  int threads = 0;
  bool allow_large = false;
};

std::pair<double, double> range(const std::string& flag, const std::string& v) {
  const auto c = v.find(':');
  try {
    if (c == std::string::npos) throw std::invalid_argument("no colon");
    std::size_t p1 = 0, p2 = 0;
    const double a = std::stod(v.substr(0, c), &p1), b = std::stod(v.substr(c + 1), &p2);
    if (p1 != c || p2 != v.size() - c - 1 || !(a > 0) || !(b >= a) || !std::isfinite(b))
      throw std::invalid_argument("bad");
    return {a, b};
  } catch (const std::exception&) {
    throw navimpact::Error(flag + " '" + navimpact::printable(v, 60) + "': expected LO:HI with 0 < LO <= HI");
  }
}

/// --causes a,b,...: the causes' names (analysis::causeName).
std::vector<na::Cause> parseCauses(const std::string& text) {
  std::vector<na::Cause> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    bool ok = false;
    for (int c = 0; c <= static_cast<int>(na::Cause::Outliers); ++c)
      if (item == na::causeName(static_cast<na::Cause>(c))) {
        out.push_back(static_cast<na::Cause>(c));
        ok = true;
      }
    if (!ok)
      throw navimpact::Error("--causes: unknown cause '" + navimpact::printable(item, 40) +
                             "' (white_noise, quantization_noise, random_walk, drift, gauss_markov, sinusoid, "
                             "level_shift, outliers)");
  }
  return out;
}

/// FLAG LO:HI within @p r: "--rate '0.5:10': rates must be in [1, 10000] Hz".
void checkRange(const char* flag, const std::string& v, const navimpact::limits::Range& r, const std::string& what) {
  const auto [a, b] = range(flag, v);
  if (!(a >= r.lo && b <= r.hi)) {
    std::string text = navimpact::limits::describe(r);
    while (!text.empty() && text.back() == ' ') text.pop_back();
    throw navimpact::Error(std::string(flag) + " '" + navimpact::printable(v, 60) + "': " + what + " must be in " + text);
  }
}

int run(const Opts& o) {
  navimpact::OutputSet out(o.out, navimpact::cli::overwriteMode(o.overwrite));
  pw::PowerOptions p;
  p.runs_per_cause = o.runs;
  p.null_runs = o.null_runs;
  std::tie(p.min_snr, p.max_snr) = range("--snr", o.snr);
  std::tie(p.ranges.min_rate_hz, p.ranges.max_rate_hz) = range("--rate", o.rate);
  if (!o.duration_h.empty()) {
    auto [a, b] = range("--duration-h", o.duration_h);
    p.ranges.min_duration_s = a * 3600.0;
    p.ranges.max_duration_s = b * 3600.0;
  } else {
    auto [a, b] = range("--samples", o.samples);
    if (a < 4096) throw navimpact::Error("--samples '" + o.samples + "': at least 4096 samples");
    p.ranges.min_samples = static_cast<std::size_t>(a);
    p.ranges.max_samples = static_cast<std::size_t>(b);
  }
  if (!o.causes.empty()) p.causes = parseCauses(o.causes);
  if (!(o.alpha > 0 && o.alpha < 0.5)) throw navimpact::Error("--alpha must be in (0, 0.5)");
  p.seed = o.seed;
  p.alpha = o.alpha;
  p.simulations = o.simulations;
  p.threads = o.threads;
  p.allow_large = o.allow_large;
  pw::checkPowerOptions(p);  // before any work
  navimpact::cli::Progress bar("diagnose-power", 1000);
  p.progress = [&bar](double f) { bar.update(static_cast<std::size_t>(f * 1000)); };
  const pw::PowerResult r = pw::runPower(p);
  bar.finish();
  const std::string table = navimpact::report::powerTable(r);
  std::ostringstream md;
  md << "# Detection power of navimpact diagnose\n\nSeed " << o.seed << ", alpha " << o.alpha << ", "
     << o.runs << " runs per cause, " << o.null_runs << " null records; SNR = effect size / detection limit "
     << "(see README \"Detection power\"); rate " << o.rate << " Hz, "
     << (o.duration_h.empty() ? "samples " + o.samples : "duration " + o.duration_h + " h") << ".\n\n"
     << table;
  out.writeText("power.md", md.str());
  out.writeText("power.json", navimpact::report::powerJson(r));
  navimpact::report::writePowerTiming(r, out);
  out.commit();
  std::cout << table << "cost: " << r.cpu_s << " s CPU, " << r.wall_s << " s wall\n"
            << "wrote " << (std::filesystem::path(o.out) / "power.md").string() << " and power.json\n";
  return 0;
}

navimpact::cli::Registrar reg(
    {"diagnose-power",
     "Detection power and null false-alarm rate of `navimpact diagnose` on simulated records with hidden effects",
     [](CLI::App& app) {
       auto o = std::make_shared<Opts>();
       app.add_option("--out", o->out, "output directory")->required();
       navimpact::cli::addOverwriteFlag(app, o->overwrite);
       const navimpact::limits::Range counts{0.0, double(navimpact::limits::kMaxMonteCarloRuns), false, ""};
       app.add_option("--runs", o->runs, "records per cause")->capture_default_str()->check(navimpact::cli::within(counts));
       app.add_option("--null-runs", o->null_runs, "null records (six channels, drawn from the model)")
           ->capture_default_str()
           ->check(navimpact::cli::within(counts));
       auto lohi = [](const char* flag, navimpact::limits::Range r, const char* what) {
         return navimpact::cli::parsedBy([=](const std::string& s) { checkRange(flag, s, r, what); }, "LO:HI");
       };
       app.add_option("--snr", o->snr, "effect size as multiples of the detection limit, drawn log-uniform LO:HI")
           ->capture_default_str()
           ->check(lohi("--snr", {0.0, 1000.0, false, ""}, "multiples of the limit"));
       app.add_option("--rate", o->rate, "sampling rate range LO:HI [Hz], log-uniform")
           ->capture_default_str()
           ->check(lohi("--rate", navimpact::limits::kImuRateHz, "rates"));
       app.add_option("--duration-h", o->duration_h, "record duration range LO:HI [h], log-uniform (e.g. 0.5:10; overrides --samples)")
           ->check(lohi("--duration-h",
                        {navimpact::limits::kDurationS.lo / 3600.0, navimpact::limits::kDurationS.hi / 3600.0, false, "h"},
                        "durations"));
       app.add_option("--samples", o->samples, "record length range LO:HI [samples], log-uniform")
           ->capture_default_str()
           ->check(lohi("--samples", {4096.0, 1e12, false, ""}, "record lengths (a wavelet variance of 12 scales needs 4096)"));
       app.add_option("--causes", o->causes, "comma-separated causes (default: all eight)")
           ->check(navimpact::cli::parsedBy([](const std::string& s) { parseCauses(s); }, "CAUSE,..."));
       app.add_option("--seed", o->seed, "root seed")->capture_default_str()->check(navimpact::cli::seedValue());
       app.add_option("--alpha", o->alpha, "family-wise level of each diagnosis")
           ->capture_default_str()
           ->check(navimpact::cli::within(navimpact::cli::kAlpha, true));
       app.add_option("--simulations", o->simulations, "Monte-Carlo simulations per channel in each diagnosis")
           ->capture_default_str()
           ->check(navimpact::cli::within(counts))
           ->check(CLI::Validator(
               [](std::string& s) { return s == "1" ? std::string("must be 0 (the closed forms) or at least 2") : std::string(); },
               ""));
       app.add_option("--threads", o->threads, "worker threads over records (0 = all cores)")
           ->check(navimpact::cli::within(navimpact::cli::kThreads));
       app.add_flag("--allow-large", o->allow_large, "run above the work and memory budgets (README \"Ranges and budgets\")");
       return [o]() { return run(*o); };
     }});

}  // namespace
