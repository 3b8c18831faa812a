// Outputs of navimpact covariance: covariance.csv, summary.json, one figure per model set.
#include "navimpact/report/covariance_report.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

#include "navimpact/core/format.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/plot/figure.hpp"

namespace navimpact::report {

using namespace analysis;

namespace {
const char* kCols[9] = {"sigma_pos_N_m",    "sigma_pos_E_m",     "sigma_pos_D_m",
                        "sigma_vel_N_mps",  "sigma_vel_E_mps",   "sigma_vel_D_mps",
                        "sigma_roll_rad",   "sigma_pitch_rad",   "sigma_yaw_rad"};

std::size_t nearest(const std::vector<double>& t, double x) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < t.size(); ++i)
    if (std::abs(t[i] - x) < std::abs(t[best] - x)) best = i;
  return best;
}
}  // namespace

void writeCovarianceStudy(const CovarianceStudyConfig& cfg, const CovarianceStudyResult& res,
                          OutputSet& out) {
  // covariance.csv
  {
    std::ostringstream csv;
    csv << "time_s,model_set,model";
    for (const char* c : kCols) csv << "," << c;
    csv << "\n";
    for (const CovarianceRun& r : res.runs) {
      for (std::size_t i = 0; i < r.t.size(); ++i) {
        csv << formatNumber(r.t[i], 6) << "," << r.model_set << "," << r.model;
        for (double v : r.sigma[i]) csv << "," << formatNumber(v, 9);
        csv << "\n";
      }
    }
    out.writeText("covariance.csv", csv.str());
  }
  // summary.json
  {
    nlohmann::json j;
    j["generator"] = "navimpact covariance";
    j["config_file"] = cfg.source;
    j["config"] = nlohmann::json::parse(cfg.echo);
    j["units"] = "SI: m, m/s, rad (roll, pitch, yaw sigmas from the N, E, D attitude-error covariance)";
    j["small_error_limit"] = {
        {"attitude_sigma_rad", kSmallErrorAttitudeSigmaRad},
        {"reason", "the filter's attitude error model is first order in psi: at 3 sigma of this limit (0.15 rad) the "
                   "neglected second-order part (|psi|/2 of the first-order one) is 7.5 %; beyond it the sigmas are "
                   "the propagated covariance of a linearisation that no longer holds, not an error bound"}};
    j["runs"] = nlohmann::json::array();
    for (const CovarianceRun& r : res.runs) {
      nlohmann::json jr;
      jr["model_set"] = r.model_set;
      jr["model"] = r.model;
      jr["model_text"] = r.model_text;
      jr["filter_states"] = r.states;
      // the eigenvalue floor of the positive-definiteness check (filter::PdCheck)
      jr["covariance_repairs"] = r.pd_repairs;
      if (r.pd_repairs > 0) {
        jr["covariance_repair_worst_eigenvalue"] = r.pd_worst_eigenvalue;
        jr["covariance_first_repair_s"] = r.pd_first_repair_s;
      }
      if (!r.notes.empty()) jr["notes"] = r.notes;  // how the model entered the filter (filter::layoutFor)
      // the small-error range of the linearisation (analysis::kSmallErrorAttitudeSigmaRad)
      jr["max_attitude_sigma_rad"] = r.max_attitude_sigma_rad;
      jr["within_small_error_range"] = r.small_error_column < 0;
      if (r.small_error_column >= 0) {
        jr["small_error_exceeded_s"] = r.small_error_exceeded_s;
        jr["small_error_exceeded_by"] = kCols[r.small_error_column];
      }
      jr["at"] = nlohmann::json::array();
      for (double ts : cfg.summary_times_s) {
        const std::size_t i = nearest(r.t, ts);
        nlohmann::json row;
        row["t_s"] = r.t[i];
        for (int c = 0; c < 9; ++c) row[kCols[c]] = r.sigma[i][c];
        jr["at"].push_back(row);
      }
      j["runs"].push_back(jr);
    }
    out.writeText("summary.json", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  }
  // one figure per model set: rows position / velocity / attitude, columns N, E, D (roll, pitch, yaw)
  for (const ModelSet& set : cfg.model_sets) {
    plot::Figure fig;
    fig.width = 1800;
    fig.height = 1300;
    fig.rows = 3;
    fig.cols = 3;
    fig.title = set.title;
    struct Panel { int col; double scale; const char* title; const char* ylabel; };
    const Panel panels[9] = {
        {0, 1.0, "position north", "σ [m]"},   {1, 1.0, "position east", "σ [m]"},
        {2, 1.0, "position down", "σ [m]"},    {3, 1.0, "velocity north", "σ [m/s]"},
        {4, 1.0, "velocity east", "σ [m/s]"},  {5, 1.0, "velocity down", "σ [m/s]"},
        {6, 1.0 / units::kDeg, "roll", "σ [deg]"}, {7, 1.0 / units::kDeg, "pitch", "σ [deg]"},
        {8, 1.0 / units::kDeg, "yaw", "σ [deg]"}};
    for (const Panel& p : panels) {
      plot::Axes ax;
      ax.title = p.title;
      ax.xlabel = "time [s]";
      ax.ylabel = p.ylabel;
      ax.legend = plot::LegendPos::TopLeft;
      int idx = 0;
      for (const CovarianceRun& r : res.runs) {
        if (r.model_set != set.name) continue;
        plot::Series s;
        s.label = r.model;
        s.x = r.t;
        s.y.reserve(r.t.size());
        for (const auto& v : r.sigma) s.y.push_back(v[p.col] * p.scale);
        s.color = plot::palette(idx);
        s.style = idx % 2 == 0 ? plot::LineStyle::Solid : plot::LineStyle::Dashed;
        ax.series.push_back(std::move(s));
        ++idx;
      }
      fig.axes.push_back(std::move(ax));
    }
    plot::savePng(fig, out.stage("covariance_" + set.name + ".png").string());
  }
}

std::string covarianceStateLayouts(const std::vector<analysis::CovarianceModel>& models) {
  std::string out;
  for (const auto& m : models) {
    out += "# " + m.model_set + " / " + m.model + ": " + std::to_string(m.entry.layout.size()) + " states\n";
    for (const auto& n : m.entry.notes) out += "# note: " + n + "\n";
    out += m.entry.layout.describe();
  }
  return out;
}

std::string covarianceSummary(const CovarianceStudyResult& res) {
  std::string out;
  char b[512];
  std::snprintf(b, sizeof b, "%-14s %-12s %9s %9s %9s %10s %9s\n", "set", "model", "t [s]", "pos N [m]",
                "vel N[m/s]", "roll [deg]", "yaw [deg]");
  out += b;
  for (const auto& r : res.runs) {
    const auto& s = r.sigma.back();
    std::snprintf(b, sizeof b, "%-14s %-12s %9.1f %9.4f %9.5f %10.5f %9.5f\n", r.model_set.c_str(),
                  r.model.c_str(), r.t.back(), s[0], s[3], s[6] / units::kDeg, s[8] / units::kDeg);
    out += b;
    for (const auto& n : r.notes) out += "  note (" + r.model_set + " / " + r.model + "): " + n + "\n";
  }
  for (const auto& r : res.runs)
    if (r.small_error_column >= 0) {
      std::snprintf(b, sizeof b,
                    "warning: %s / %s: %s sigma above the filter's small-error range (%.3g deg) from t = %.1f s on "
                    "(largest attitude sigma %.3g deg): from there on the sigmas are not an error bound\n",
                    r.model_set.c_str(), r.model.c_str(),
                    r.small_error_column == 6 ? "roll" : r.small_error_column == 7 ? "pitch" : "yaw",
                    kSmallErrorAttitudeSigmaRad / units::kDeg, r.small_error_exceeded_s,
                    r.max_attitude_sigma_rad / units::kDeg);
      out += b;
    }
  for (const auto& r : res.runs)
    if (r.pd_repairs > 0) {
      std::snprintf(b, sizeof b,
                    "note: %s / %s: covariance repaired %d time(s) by the eigenvalue floor (rounding; worst eigenvalue "
                    "%.3g on the correlation scale, first at t = %.1f s)\n",
                    r.model_set.c_str(), r.model.c_str(), r.pd_repairs, r.pd_worst_eigenvalue, r.pd_first_repair_s);
      out += b;
    }
  return out;
}

}  // namespace navimpact::report
