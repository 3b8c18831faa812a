// IMU error model files (YAML), read through the one configuration reader
// (core/config.hpp): every unknown or duplicate key is an error naming the file
// and the dotted key path, so a typo never silently means "no error".
#include "navimpact/stochastic/model_file.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

#include "navimpact/core/config.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/imu_series.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/core/text_io.hpp"

namespace navimpact::stochastic {

namespace {

constexpr const char* kSensorKeys[] = {"accelerometer", "gyroscope"};
constexpr const char* kModelKeysHelp =
    "rate_hz, description, accelerometer, gyroscope, gyro_x, gyro_y, gyro_z, acc_x, acc_y, acc_z";

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

/// Build the six axes of one model node (single-model root or models.NAME).
ImuModel readModel(const ConfigNode& node, double default_rate) {
  if (!node.isMap()) throw node.error("expected a map of " + std::string(kModelKeysHelp));
  node.allowKeys({"rate_hz", "description", "accelerometer", "gyroscope", "gyro_x", "gyro_y", "gyro_z", "acc_x",
                  "acc_y", "acc_z"});
  ImuModel m;
  m.rate_hz = default_rate;
  node.read("rate_hz", m.rate_hz, limits::kImuRateHz);
  if (!(m.rate_hz > 0.0)) throw node.error("rate_hz", "missing (the rate the per-sample parameters refer to, Hz)");

  auto parseAt = [&](const std::string& key) {
    const ConfigNode v = node.child(key);
    // an empty value (`accelerometer:`) loaded as a perfect sensor without a word
    if (v.isNull()) throw node.error(key, "is empty: write a model string such as \"WN(sigma=1e-3)\", or \"none\" for no error");
    if (!v.isScalar()) throw node.error(key, "expected a model string such as \"WN(sigma=1e-3)\"");
    try {
      return parseTerms(v.asText(), m.rate_hz);
    } catch (const Error& e) {
      throw node.error(key, e.what());
    }
  };
  // Sensor keys first, then per-axis keys override.
  for (const char* sensor : kSensorKeys) {
    if (!node.has(sensor)) continue;
    const auto terms = parseAt(sensor);
    const bool acc = std::string(sensor) == "accelerometer";
    for (int i = 0; i < 6; ++i)
      if ((i >= 3) == acc) m.axis[i].terms = terms;
  }
  for (int i = 0; i < 6; ++i)
    if (node.has(kChannelNames[i])) m.axis[i].terms = parseAt(kChannelNames[i]);
  for (int i = 0; i < 6; ++i) {
    m.axis[i].rate_hz = m.rate_hz;
    try {
      validate(m.axis[i]);
    } catch (const Error& e) {
      throw node.error(kChannelNames[i], e.what());
    }
  }
  return m;
}

ConfigNode loadYaml(const std::string& file) {
  const std::string why = unreadableReason(file);
  if (!why.empty()) throw Error(printable(file, 1024) + ": cannot open model file (" + why + ")");
  return ConfigNode::load(file);
}

/// Split "FILE:NAME"; a spec naming an existing file is a FILE.
void splitSpec(const std::string& spec, std::string& file, std::string& name) {
  file = spec;
  name.clear();
  std::error_code ec;  // (the throwing form fails on a name longer than the system allows)
  if (std::filesystem::is_regular_file(spec, ec)) return;
  const auto c = spec.rfind(':');
  if (c != std::string::npos && c > 0) {
    file = spec.substr(0, c);
    name = spec.substr(c + 1);
  }
}

std::vector<std::string> modelNames(const ConfigNode& root) {
  if (!root.has("models")) return {};
  const ConfigNode models = root.child("models");
  if (!models.isMap() || models.keys().empty()) throw root.error("models", "expected a map of named models");
  return models.keys();
}

/// The model @p name ("" = the only one) of a parsed model file.
ImuModel modelFrom(const ConfigNode& root, std::string name) {
  const std::string& file = root.file();
  const auto names = modelNames(root);
  ImuModel m;
  if (names.empty()) {
    if (!name.empty())
      throw Error(file + ": holds a single model (no 'models:' map); cannot select '" + printable(name) +
                  "' - use '" + file + "' alone");
    m = readModel(root, 0.0);
    m.source = file;
  } else {
    // Root of a multi-model file: rate_hz (default for all), description, models.
    root.allowKeys({"models", "rate_hz", "description"});
    double rate = 0.0;
    root.read("rate_hz", rate, limits::kImuRateHz);
    if (name.empty()) {
      if (names.size() != 1)
        throw Error(file + ": holds " + std::to_string(names.size()) +
                    " models; select one as FILE:NAME (available: " + printable(join(names), 200) + ")");
      name = names.front();
    }
    bool found = false;
    for (const auto& n : names) found = found || n == name;
    if (!found)
      throw Error(file + ": no model named '" + printable(name) + "' (available: " + printable(join(names), 200) + ")");
    m = readModel(root.map("models").child(name), rate);
    m.name = name;
    m.source = file + ":" + name;
  }
  return m;
}

}  // namespace

const Model& ImuModel::forChannel(const std::string& channel) const {
  const int i = channelIndex(channel);
  if (i < 0) throw Error("unknown IMU channel '" + channel + "' (expected gyro_x..gyro_z, acc_x..acc_z)");
  return axis[i];
}

Model& ImuModel::forChannel(const std::string& channel) {
  return const_cast<Model&>(static_cast<const ImuModel&>(*this).forChannel(channel));
}

std::vector<std::string> listModels(const std::string& file) {
  InputScope scope(file);
  return modelNames(loadYaml(file));
}

ImuModel loadImuModel(const std::string& spec) {
  InputScope scope(spec);
  std::string file, name;
  splitSpec(spec, file, name);
  return modelFrom(loadYaml(file), name);
}

ImuModel parseImuModel(const std::string& text, const std::string& source, const std::string& name) {
  return modelFrom(ConfigNode::parse(text, source), name);
}

std::string toYaml(const ImuModel& m, const std::string& comment) {
  std::string s;
  if (!comment.empty()) {
    std::size_t a = 0;
    while (a <= comment.size()) {
      const auto b = comment.find('\n', a);
      const std::string l = comment.substr(a, b == std::string::npos ? std::string::npos : b - a);
      s += "# " + l + "\n";
      if (b == std::string::npos) break;
      a = b + 1;
    }
  }
  s += "# IMU error model: per-sample parameters at rate_hz (WN sigma, QN Q, RW gamma,\n"
       "# DR omega per sample; GM sigma stationary, T in s; SIN amp, freq in Hz).\n";
  s += "rate_hz: " + formatNumber(m.rate_hz, 17) + "  # Hz\n";
  auto q = [](const Model& a) { return "\"" + formatTerms(a.terms, 17) + "\""; };
  const bool gyro_same = m.axis[0].terms == m.axis[1].terms && m.axis[0].terms == m.axis[2].terms;
  const bool acc_same = m.axis[3].terms == m.axis[4].terms && m.axis[3].terms == m.axis[5].terms;
  if (acc_same) s += "accelerometer: " + q(m.axis[3]) + "  # m/s^2\n";
  if (gyro_same) s += "gyroscope: " + q(m.axis[0]) + "  # rad/s\n";
  for (int i = 0; i < 6; ++i) {
    const bool acc = i >= 3;
    if ((acc && acc_same) || (!acc && gyro_same)) continue;
    s += std::string(kChannelNames[i]) + ": " + q(m.axis[i]) + (acc ? "  # m/s^2\n" : "  # rad/s\n");
  }
  return s;
}

ImuModel convertRate(const ImuModel& m, double new_rate_hz) {
  ImuModel out = m;
  out.rate_hz = new_rate_hz;
  for (int i = 0; i < 6; ++i) {
    Model a = m.axis[i];
    a.rate_hz = m.rate_hz;
    out.axis[i] = convertRate(a, new_rate_hz);
  }
  return out;
}

ImuModel atRate(const ImuModel& m, double rate_hz, std::vector<std::string>* notes) {
  if (std::abs(m.rate_hz - rate_hz) <= 1e-9 * rate_hz) return m;
  if (notes)
    notes->push_back("model " + m.source + " given at " + formatNumber(m.rate_hz) + " Hz, converted exactly to " +
                     formatNumber(rate_hz) + " Hz (the same continuous-time processes)");
  return convertRate(m, rate_hz);
}

}  // namespace navimpact::stochastic
