// Outputs of navimpact wv: wv.json, wv.csv, WV figures, console summary.
#include "navimpact/report/wv_report.hpp"

#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

#include "navimpact/core/format.hpp"
#include "navimpact/core/units.hpp"
#include "navimpact/plot/figure.hpp"

namespace navimpact::report {

namespace {

std::string squaredUnit(units::Quantity q) {
  return q == units::Quantity::AngularRate ? "(rad/s)^2" : "(m/s^2)^2";
}

std::vector<double> toStd(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

}  // namespace

void writeWvOutputs(const gmwm::RecordingWv& w, const std::string& input_json, OutputSet& out) {
  const bool robust = w.options.robust;
  nlohmann::ordered_json j;
  j["input"] = nlohmann::ordered_json::parse(input_json);
  j["estimator"] = {
      {"wavelet", "Haar MODWT, scales 2^j samples, j = 1..floor(log2 N), boundary coefficients dropped"},
      {"type", robust ? "robust (Tukey biweight M-scale)" : "classical (mean of squares)"},
      {"ci", robust ? "95 % eta3 chi-square CI widened by 1/sqrt(eff)" : "95 % eta3 chi-square CI"},
      {"alpha", w.options.alpha}};
  if (robust) j["estimator"]["eff"] = w.options.eff;
  std::ostringstream csv;
  csv << "channel,j,tau_s,wv,ci_low,ci_high\n";
  csv.precision(17);
  for (const auto& c : w.channels) {
    nlohmann::ordered_json jc = {{"name", c.name},
                                 {"unit", squaredUnit(c.quantity)},
                                 {"tau_s", toStd(c.wv.tauSeconds())},
                                 {"wv", toStd(c.wv.wv)},
                                 {"ci_low", toStd(c.wv.ci_low)},
                                 {"ci_high", toStd(c.wv.ci_high)}};
    if (!c.wv.mad_scales.empty()) {
      std::vector<double> t;
      for (int s : c.wv.mad_scales) t.push_back(c.wv.tau[s] / w.rate_hz);
      jc["mad_scales_tau_s"] = t;  // robust: scales where the biweight broke down and the MAD scale is used
    }
    if (!c.wv.classical_scales.empty()) {
      std::vector<double> t;
      for (int s : c.wv.classical_scales) t.push_back(c.wv.tau[s] / w.rate_hz);
      jc["classical_scales_tau_s"] = t;  // robust: scales with more than half the coefficients zero (quantised)
    }
    if (w.allan)
      jc["allan"] = {{"tau_s", c.allan_tau_s}, {"adev", c.adev}, {"unit", units::siUnit(c.quantity)}};
    j["channels"].push_back(jc);
    for (int i = 0; i < c.wv.scales(); ++i)
      csv << c.name << ',' << i + 1 << ',' << c.wv.tau[i] / w.rate_hz << ',' << c.wv.wv[i] << ','
          << c.wv.ci_low[i] << ',' << c.wv.ci_high[i] << '\n';
  }
  out.writeText("wv.json", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  out.writeText("wv.csv", csv.str());
  // One log-log figure per sensor: the axes present, each with its CI band.
  for (int sensor = 0; sensor < 2; ++sensor) {
    const auto q = sensor == 0 ? units::Quantity::AngularRate : units::Quantity::SpecificForce;
    plot::Axes ax;
    ax.logx = ax.logy = true;
    ax.xlabel = "scale τ [s]";
    ax.ylabel = std::string("wavelet variance ν² [") + squaredUnit(q) + "]";
    int k = 0;
    for (const auto& c : w.channels) {
      if (c.quantity != q) continue;
      const auto col = plot::palette(k++);
      const auto tau = toStd(c.wv.tauSeconds());
      ax.bands.push_back({"", tau, toStd(c.wv.ci_low), toStd(c.wv.ci_high), col, 0.2});
      ax.series.push_back({c.name, tau, toStd(c.wv.wv), col, plot::LineStyle::Solid, plot::Marker::FilledCircle});
    }
    if (k == 0) continue;
    plot::Figure fig;
    fig.title = std::string(sensor == 0 ? "Gyroscope" : "Accelerometer") + " Haar wavelet variance" +
                (robust ? " (robust)" : "") + " with 95 % CI";
    fig.axes = {ax};
    const std::string name = sensor == 0 ? "wv_gyroscope.png" : "wv_accelerometer.png";
    plot::savePng(fig, out.stage(name).string());
  }
}

std::string wvSummary(const gmwm::RecordingWv& w) {
  std::ostringstream os;
  os << "wavelet variance of " << w.source << ": " << w.samples << " samples at " << formatNumber(w.rate_hz)
     << " Hz, " << (w.channels.empty() ? 0 : w.channels[0].wv.scales()) << " scales"
     << (w.options.robust ? " (robust)" : "") << "\n";
  char line[256];
  std::snprintf(line, sizeof line, "  %-8s %-11s %-22s %-22s\n", "channel", "unit", "WV at smallest tau",
                "WV at largest tau");
  os << line;
  for (const auto& c : w.channels) {
    const int J = c.wv.scales() - 1;
    const std::string lo = formatNumber(c.wv.wv[0]) + " (" + formatNumber(c.wv.tau[0] / w.rate_hz) + " s)";
    const std::string hi = formatNumber(c.wv.wv[J]) + " (" + formatNumber(c.wv.tau[J] / w.rate_hz) + " s)";
    std::snprintf(line, sizeof line, "  %-8s %-11s %-22s %-22s\n", c.name.c_str(),
                  squaredUnit(c.quantity).c_str(), lo.c_str(), hi.c_str());
    os << line;
  }
  return os.str();
}

}  // namespace navimpact::report
