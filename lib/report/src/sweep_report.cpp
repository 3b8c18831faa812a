// Sweep outputs: the verdicts (JSON), the map and the paper's threshold
// (Markdown), one heat map per column (PNG).
#include "navimpact/report/sweep_report.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <nlohmann/json.hpp>

#include "navimpact/core/format.hpp"
#include "navimpact/plot/figure.hpp"
#include "navimpact/report/study_report.hpp"
#include "navimpact/report/timing.hpp"

namespace navimpact::report {

using namespace analysis;
using nlohmann::json;

namespace {

json jnum(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }
json jtime(double x) { return x >= 0.0 ? json(x) : json(nullptr); }

const char* kRules =
    "accuracy: a model is worse than the set's reference when the one-sided paired t-test on "
    "d_i = e_model,i^2 - (1 + margin)^2 e_reference,i^2 (horizontal position error at the outage end, run i) "
    "rejects at alpha / K (K = non-reference models of the set); consistency: position ANEES inside the "
    "two-sided 95 % chi-square band of the runs (3 dof) widened by the margin, [lo / (1 + margin), hi (1 + margin)], "
    "or, when the reference's own ANEES is outside that band, within a factor (1 + margin) of the reference's; "
    "sufficient = not worse and consistent; recommended = the sufficient model with the fewest filter states";
const char* kThresholdRule =
    "white-noise threshold: the time into the outage from which the set's white-noise model departs from the "
    "reference at every later outage epoch: RMS horizontal error above (1 + margin) times the reference's, or "
    "consistency lost (the cells' consistency rule); the estimated effect, which converges as runs are added; "
    "interval: 2.5 and 97.5 percentiles over bootstrap resamples of the runs (resamples where it never departs "
    "for good count as beyond the longest outage); significantly_insufficient_from_s: where the cells' test "
    "finds it insufficient at every later epoch (needs evidence, so later with few runs)";

json verdictJson(const CandidateVerdict& v) {
  return {{"label", v.label},
          {"states", v.states},
          {"rms_horizontal_error_m", jnum(v.rms_h_m)},
          {"ratio_to_reference", jnum(v.ratio)},
          {"p_worse", jnum(v.p_worse)},
          {"runs_worse", v.runs_worse},
          {"anees_pos", jnum(v.anees)},
          {"nees_runs", v.nees_runs},
          {"anees_band", {jnum(v.band_lo), jnum(v.band_hi)}},
          {"p_nees_vs_reference", jnum(v.p_nees_vs_ref)},
          {"worse", v.worse},
          {"consistent", v.consistent},
          {"consistent_as_reference", v.consistent_as_reference},
          {"sufficient", v.sufficient}};
}

// ------------------------------------------------------------------ figures

plot::Color mix(plot::Color a, plot::Color b, double t) {
  t = std::clamp(t, 0.0, 1.0);
  auto m = [&](std::uint8_t x, std::uint8_t y) {
    return static_cast<std::uint8_t>(std::lround(x + (double(y) - double(x)) * t));
  };
  return {m(a.r, b.r), m(a.g, b.g), m(a.b, b.b)};
}

/// Sufficient: light blue getting deeper as the ratio approaches 1 + margin;
/// insufficient: orange to vermillion with the log ratio (Okabe & Ito hues).
plot::Color cellColor(const CandidateVerdict& v, double margin) {
  const plot::Color white{255, 255, 255}, sky{86, 180, 233}, orange{230, 159, 0}, vermillion{213, 94, 0};
  if (v.sufficient) {
    const double t = std::isfinite(v.ratio) ? std::clamp((v.ratio - 1.0) / std::max(margin, 1e-3), 0.0, 1.0) : 0.0;
    return mix(mix(white, sky, 0.35), sky, t);
  }
  const double t = std::isfinite(v.ratio) && v.ratio > 1.0 ? std::log10(v.ratio) / std::log10(10.0) : 0.0;
  return mix(orange, vermillion, t);
}

std::string cellText(const CandidateVerdict& v) {
  std::string s = formatReadable(v.ratio, 3);
  if (v.worse || !v.consistent) {
    s += " \u2717";  // ✗
    if (v.worse) s += "e";
    if (!v.consistent) s += "\u03bd";  // ν: NEES outside the band
  }
  return s;
}

void drawMap(const SweepResults& r, std::size_t c, const std::string& path) {
  const auto& meta = r.meta;
  const auto& cr = r.columns[c];
  plot::Figure fig;
  fig.title = "Model-sufficiency map: " + meta.columns[c].name + " (" + std::to_string(r.runs) + " runs)";
  fig.rows = static_cast<int>(cr.sets.size());
  fig.cols = 1;
  std::size_t max_models = 1;
  for (const auto& s : cr.sets) max_models = std::max(max_models, s.set.models.size());
  fig.width = std::max(900, 220 + 110 * static_cast<int>(meta.durations_s.size()));
  fig.height = std::min(20000, 120 + fig.rows * (110 + 48 * static_cast<int>(max_models)));
  const std::size_t D = meta.durations_s.size();
  for (const auto& sr : cr.sets) {
    plot::Axes ax;
    ax.grid = false;
    ax.legend = plot::LegendPos::None;
    const std::size_t S = sr.set.models.size();
    ax.xlim = std::make_pair(0.0, double(D));
    ax.ylim = std::make_pair(0.0, double(S));
    ax.title = sr.set.name + ": " + sr.threshold.white_noise + " departs from " + sr.threshold.reference + " from " +
               thresholdText(sr.threshold) + ", 95 % " + intervalText(sr.threshold) +
               (sr.cells.empty() || sr.cells.back().reference_consistent ? "" : " (reference inconsistent)");
    ax.xlabel = "GNSS outage duration";
    for (std::size_t j = 0; j < D; ++j) ax.xticks.push_back({j + 0.5, formatReadable(meta.durations_s[j]) + " s"});
    for (std::size_t i = 0; i < S; ++i) ax.yticks.push_back({double(S - 1 - i) + 0.5, sr.set.models[i]});
    for (std::size_t j = 0; j < D; ++j)
      for (std::size_t i = 0; i < S; ++i) {
        const CandidateVerdict& v = sr.cells[j].models[i];
        plot::Cell cell;
        cell.x0 = double(j);
        cell.x1 = double(j + 1);
        cell.y0 = double(S - 1 - i);
        cell.y1 = double(S - i);
        cell.fill = cellColor(v, meta.margin);
        cell.text = cellText(v);
        cell.text_color = v.sufficient ? plot::Color{34, 34, 34} : plot::Color{255, 255, 255};
        if (sr.cells[j].recommended == v.label) {
          cell.outline = 4;
          cell.outline_color = {0, 0, 0};
        }
        ax.cells.push_back(cell);
      }
    fig.axes.push_back(ax);
  }
  plot::savePng(fig, path);
}

// ------------------------------------------------------------------ report

std::string reportMd(const SweepResults& r, const std::vector<std::string>& maps) {
  const auto& meta = r.meta;
  std::ostringstream md;
  md << "# Model-sufficiency map: which IMU model is enough for this application?\n\n";
  md << "Config `" << meta.config_file << "`, " << r.runs << " paired runs per cell (seed " << meta.seed
     << "), GNSS outage from " << formatReadable(meta.outage_start_s) << " s, durations";
  for (double d : meta.durations_s) md << " " << formatReadable(d);
  md << " s; " << meta.columns.size() << " column(s) of GNSS quality x barometer x IMU rate; margin "
     << formatReadable(100 * meta.margin) << " %, alpha " << formatReadable(meta.alpha) << ".\n\n";

  md << "## The paper's threshold, per sensor\n\n"
     << "Khaghani et al. (2019): \"at least 10 seconds is needed to observe a meaningful difference\" between "
        "simple and complex models (static covariance analysis). Here, per model set and column: the outage "
        "duration from which white noise alone is no longer sufficient, for good, with its 95 % bootstrap "
        "interval ("
     << meta.bootstrap << " resamples).\n\n"
     << "| set | column | white-noise model | departs for good from | 95 % interval | first departure | "
        "significantly insufficient from |\n"
     << "|---|---|---|---:|---:|---:|---:|\n";
  for (std::size_t c = 0; c < meta.columns.size(); ++c)
    for (const auto& sr : r.columns[c].sets) {
      const auto& t = sr.threshold;
      if (!t.defined) continue;
      auto when = [&](double v) { return v < 0 ? "> " + formatReadable(t.scanned_to_s) + " s" : formatReadable(v) + " s"; };
      md << "| " << sr.set.title << " | " << meta.columns[c].name << " | " << t.white_noise << " vs "
         << t.reference << " | **" << thresholdText(t) << "** | " << intervalText(t) << " | "
         << (t.first_departure_s < 0 ? "never" : formatReadable(t.first_departure_s) + " s") << " | " << when(t.significant_s)
         << " |\n";
    }
  md << "\nDeparts: RMS horizontal error more than " << formatReadable(100 * meta.margin)
     << " % above the reference's, or consistency lost; the threshold is this estimated effect. \"Significantly "
        "insufficient\" is where the map's test has the evidence (it moves earlier as runs are added); between "
        "the two a cell can read sufficient: not yet shown to be worse.\n\n";
  md << "## The map\n\nThe recommended model per outage duration (the simplest sufficient one; `none`: no model "
        "of the set is sufficient). \"reference inconsistent\": the reference's own position ANEES is outside the "
        "band, so the models are judged as consistent when they are as consistent as the reference.\n\n";
  for (std::size_t c = 0; c < meta.columns.size(); ++c) {
    md << "### " << meta.columns[c].name << "\n\n![map](" << maps[c] << ")\n\n| outage [s] |";
    for (const auto& sr : r.columns[c].sets) md << " " << sr.set.title << " |";
    md << "\n|---:|";
    for (std::size_t s = 0; s < r.columns[c].sets.size(); ++s) md << "---|";
    md << "\n";
    for (std::size_t j = 0; j < meta.durations_s.size(); ++j) {
      md << "| " << formatReadable(meta.durations_s[j]) << " |";
      for (const auto& sr : r.columns[c].sets) {
        const auto& cell = sr.cells[j];
        md << " " << (cell.recommended.empty() ? "none" : cell.recommended)
           << (cell.reference_consistent ? "" : " (reference inconsistent)") << " |";
      }
      md << "\n";
    }
    md << "\n";
  }
  md << "Heat maps: cell text = RMS horizontal error at the outage end / the reference's; ✗ marks an "
        "insufficient model (e: significantly worse than the reference by more than the margin; ν: position "
        "ANEES outside the widened band, or, where the reference is inconsistent, not within the margin of the "
        "reference's); blue = sufficient, orange to vermillion = insufficient; the "
        "recommended model is framed.\n\n";

  md << "---\n\n## Evidence per cell\n\n";
  for (std::size_t c = 0; c < meta.columns.size(); ++c) {
    md << "### " << meta.columns[c].name << "\n\n" << meta.columns[c].settings << "\n\n";
    for (const auto& sr : r.columns[c].sets) {
      md << "**" << sr.set.title << "** (reference " << sr.set.reference << ")\n\n"
         << "| outage [s] | model | states | RMS horiz. [m] | ratio | p worse | runs worse | ANEES pos | band | "
            "p NEES vs ref | verdict |\n|---:|---|---:|---:|---:|---:|---:|---:|---|---:|---|\n";
      for (const auto& cell : sr.cells)
        for (const auto& v : cell.models)
          md << "| " << formatReadable(cell.duration_s) << " | " << v.label << (cell.recommended == v.label ? " **(rec.)**" : "")
             << " | " << v.states << " | " << formatReadable(v.rms_h_m) << " | " << formatFixed(v.ratio, 3) << " | " << formatReadable(v.p_worse, 2)
             << " | " << v.runs_worse << "/" << r.runs << " | " << formatReadable(v.anees) << " | [" << formatFixed(v.band_lo, 2)
             << ", " << formatFixed(v.band_hi, 2) << "] | " << formatReadable(v.p_nees_vs_ref, 2) << " | "
             << (v.sufficient ? "sufficient" : std::string("insufficient") + (v.worse ? ", worse" : "") +
                                                   (!v.consistent ? ", NEES outside band" : ""))
             << (v.consistent_as_reference ? " (as consistent as the reference)" : "")
             << " |\n";
      md << "\n";
    }
    for (const auto& n : meta.columns[c].notices) md << "- note: " << n << "\n";
    if (!meta.columns[c].notices.empty()) md << "\n";
  }
  md << "## Rules\n\n- " << kRules << ".\n- " << kThresholdRule << ".\n- Every column uses the same seed (common "
     << "random numbers); an outage of d seconds is the first d seconds of the longest one, so one set of runs "
        "serves every duration of a column.\n";
  return md.str();
}

}  // namespace

std::string thresholdText(const WnThreshold& t) {
  if (!t.defined) return "n/a";
  if (t.departs_s < 0) return "> " + formatReadable(t.scanned_to_s) + " s";
  return formatReadable(t.departs_s) + " s";
}
std::string intervalText(const WnThreshold& t) {
  if (!t.defined) return "n/a";
  auto b = [&](double v) { return v < 0 ? "> " + formatReadable(t.scanned_to_s) : formatReadable(v); };
  return "[" + b(t.lo_s) + ", " + b(t.hi_s) + "] s";
}


std::string sweepJson(const SweepResults& r) {
  const auto& meta = r.meta;
  json j;
  json s;
  provenanceJson(meta, s);
  s["inputs_hash"] = meta.inputs_hash;
  s["seed_rule"] =
      "every column runs the study with this seed: run i uses deriveSeed(seed, i) (see study.json's seed_rule); "
      "bootstrap of column c, set s: mt19937_64(deriveSeed(deriveSeed(seed, 0x5EE9B007), 1000 c + s))";
  s["runs"] = r.runs;
  s["margin"] = meta.margin;
  s["alpha"] = meta.alpha;
  s["bootstrap"] = meta.bootstrap;
  s["rules"] = kRules;
  s["threshold_rule"] = kThresholdRule;
  s["paper_threshold"] = "at least 10 s of outage to observe a meaningful difference (Khaghani et al. 2019)";
  j["sweep"] = s;
  json axes;
  axes["outage_start_s"] = meta.outage_start_s;
  axes["durations_s"] = meta.durations_s;
  json g = json::array();
  for (const auto& q : meta.gnss)
    g.push_back({{"name", q.name},
                 {"rate_hz", q.gnss.rate_hz},
                 {"sigma_pos_h_m", q.gnss.sigma_pos_h_m},
                 {"sigma_pos_v_m", q.gnss.sigma_pos_v_m},
                 {"sigma_vel_h_mps", q.gnss.sigma_vel_h_mps},
                 {"sigma_vel_v_mps", q.gnss.sigma_vel_v_mps}});
  axes["gnss"] = g;
  axes["baro"] = meta.baro;
  axes["imu_rate_hz"] = meta.imu_rates_hz;
  j["axes"] = axes;
  json cols = json::array();
  for (std::size_t c = 0; c < meta.columns.size(); ++c) {
    const auto& mc = meta.columns[c];
    json col;
    col["name"] = mc.name;
    col["gnss"] = meta.gnss[mc.axes.gnss].name;
    col["baro"] = bool(meta.baro[mc.axes.baro]);
    col["imu_rate_hz"] = meta.imu_rates_hz[mc.axes.rate];
    col["settings"] = mc.settings;
    col["notices"] = mc.notices;
    col["map"] = "map_" + std::to_string(c + 1) + ".png";
    json sets = json::array();
    for (const auto& sr : r.columns[c].sets) {
      json js;
      js["name"] = sr.set.name;
      js["title"] = sr.set.title;
      js["reference"] = sr.set.reference;
      js["white_noise"] = sr.set.white_noise;
      json cells = json::array();
      for (const auto& cell : sr.cells) {
        json jc;
        jc["duration_s"] = cell.duration_s;
        jc["recommended"] = cell.recommended.empty() ? json(nullptr) : json(cell.recommended);
        jc["reference_consistent"] = cell.reference_consistent;
        json ms = json::array();
        for (const auto& v : cell.models) ms.push_back(verdictJson(v));
        jc["models"] = ms;
        cells.push_back(jc);
      }
      js["cells"] = cells;
      const auto& t = sr.threshold;
      js["white_noise_threshold"] = {{"defined", t.defined},
                                     {"departs_for_good_from_s", jtime(t.departs_s)},
                                     {"interval_95_s", {jtime(t.lo_s), jtime(t.hi_s)}},
                                     {"bootstrap_never_departs", t.censored},
                                     {"first_departure_s", jtime(t.first_departure_s)},
                                     {"significantly_insufficient_from_s", jtime(t.significant_s)},
                                     {"scanned_to_s", t.scanned_to_s}};
      sets.push_back(js);
    }
    col["sets"] = sets;
    cols.push_back(col);
  }
  j["columns"] = cols;
  return j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

void writeSweepOutputs(const SweepResults& r, OutputSet& out) {
  out.writeText("sweep.json", sweepJson(r));
  std::vector<std::string> maps;
  for (std::size_t c = 0; c < r.columns.size(); ++c) {
    maps.push_back("map_" + std::to_string(c + 1) + ".png");
    drawMap(r, c, out.stage(maps.back()).string());
  }
  out.writeText("report.md", reportMd(r, maps));
}

void writeSweepTiming(double wall_s, const SweepResults& r, OutputSet& out) {
  writeTiming(out, {{"wall_s", wall_s}, {"filter_steps", r.filter_steps}, {"us_per_filter_step", r.us_per_filter_step}});
}

void writeSweepShardTiming(const SweepRuns& r, OutputSet& out) {
  writeTiming(out, {{"filter_steps", r.filter_steps}, {"filter_wall_s", r.filter_wall_s}});
}

}  // namespace navimpact::report
