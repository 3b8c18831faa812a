// IMU error model files (YAML). Strict: every unknown key is an error naming
// the file and the dotted key path, so a typo never silently means "no error".
#include "navimpact/stochastic/model_file.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/imu_series.hpp"
#include "navimpact/stochastic/model_text.hpp"
#include "navimpact/core/limits.hpp"

namespace navimpact::stochastic {

namespace {

constexpr const char* kSensorKeys[] = {"accelerometer", "gyroscope"};
constexpr const char* kModelKeysHelp =
    "rate_hz, description, accelerometer, gyroscope, gyro_x, gyro_y, gyro_z, acc_x, acc_y, acc_z";

bool isModelKey(const std::string& k) {
  if (k == "rate_hz" || k == "description" || k == "accelerometer" || k == "gyroscope") return true;
  return channelIndex(k) >= 0;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

/// Keys of a YAML map in file order; duplicate keys are an error.
std::vector<std::string> mapKeys(const YAML::Node& n, const std::string& file,
                                 const std::string& prefix) {
  std::vector<std::string> keys;
  std::set<std::string> seen;
  for (const auto& kv : n) {
    const std::string k = kv.first.as<std::string>();
    if (!seen.insert(k).second)
      throw keyError(file, prefix + k, "duplicate key (line " +
                                           std::to_string(kv.first.Mark().line + 1) + ")");
    keys.push_back(k);
  }
  return keys;
}

double readRate(const YAML::Node& n, const std::string& file, const std::string& key) {
  if (!n.IsScalar()) throw keyError(file, key, "expected a number in Hz");
  double v = 0.0;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    throw keyError(file, key, "expected a number in Hz, found '" + n.Scalar() + "'");
  }
  return limits::check(file, key, v, limits::kImuRateHz);
}

/// Build the six axes of one model node (single-model root or models.NAME).
ImuModel readModel(const YAML::Node& node, const std::string& file, const std::string& prefix,
                   double default_rate) {
  if (!node.IsMap()) throw keyError(file, prefix.empty() ? "(root)" : prefix.substr(0, prefix.size() - 1),
                                    "expected a map of " + std::string(kModelKeysHelp));
  const auto keys = mapKeys(node, file, prefix);
  for (const auto& k : keys)
    if (!isModelKey(k)) throw keyError(file, prefix + k, "unknown key (expected " + std::string(kModelKeysHelp) + ")");
  ImuModel m;
  m.rate_hz = node["rate_hz"] ? readRate(node["rate_hz"], file, prefix + "rate_hz") : default_rate;
  if (!(m.rate_hz > 0.0))
    throw keyError(file, prefix + "rate_hz", "missing (the rate the per-sample parameters refer to, Hz)");

  auto parseAt = [&](const std::string& key) {
    const YAML::Node v = node[key];
    if (v.IsNull()) return std::vector<Process>{};
    if (!v.IsScalar()) throw keyError(file, prefix + key, "expected a model string such as \"WN(sigma=1e-3)\"");
    try {
      return parseTerms(v.Scalar(), m.rate_hz);
    } catch (const Error& e) {
      throw keyError(file, prefix + key, e.what());
    }
  };
  // Sensor keys first, then per-axis keys override.
  for (const char* sensor : kSensorKeys) {
    if (!node[sensor]) continue;
    const auto terms = parseAt(sensor);
    const bool acc = std::string(sensor) == "accelerometer";
    for (int i = 0; i < 6; ++i)
      if ((i >= 3) == acc) m.axis[i].terms = terms;
  }
  for (int i = 0; i < 6; ++i)
    if (node[kChannelNames[i]]) m.axis[i].terms = parseAt(kChannelNames[i]);
  for (int i = 0; i < 6; ++i) {
    m.axis[i].rate_hz = m.rate_hz;
    try {
      validate(m.axis[i]);
    } catch (const Error& e) {
      throw keyError(file, prefix + kChannelNames[i], e.what());
    }
  }
  return m;
}

YAML::Node loadYaml(const std::string& file) {
  if (!std::filesystem::is_regular_file(file))
    throw Error(file + ": cannot open model file (no such file)");
  try {
    return YAML::LoadFile(file);
  } catch (const YAML::ParserException& e) {
    throw fileError(file, static_cast<std::size_t>(e.mark.line + 1), "YAML syntax error: " + printable(e.msg, 120));
  } catch (const YAML::Exception& e) {
    throw Error(file + ": cannot read model file: " + e.what());
  }
}

/// Split "FILE:NAME"; a spec naming an existing file is a FILE.
void splitSpec(const std::string& spec, std::string& file, std::string& name) {
  file = spec;
  name.clear();
  if (std::filesystem::is_regular_file(spec)) return;
  const auto c = spec.rfind(':');
  if (c != std::string::npos && c > 0) {
    file = spec.substr(0, c);
    name = spec.substr(c + 1);
  }
}

std::vector<std::string> modelNames(const YAML::Node& root, const std::string& file) {
  std::vector<std::string> names;
  if (!root.IsMap() || !root["models"]) return names;
  const YAML::Node models = root["models"];
  if (!models.IsMap() || models.size() == 0)
    throw keyError(file, "models", "expected a map of named models");
  return mapKeys(models, file, "models.");
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
  return modelNames(loadYaml(file), file);
}

static ImuModel loadImuModelImpl(const std::string& spec) {
  InputScope scope(spec);
  std::string file, name;
  splitSpec(spec, file, name);
  const YAML::Node root = loadYaml(file);
  if (!root.IsMap()) throw Error(file + ": expected a YAML map (rate_hz, accelerometer, gyroscope, ... or models)");
  const auto names = modelNames(root, file);
  ImuModel m;
  if (names.empty()) {
    if (!name.empty())
      throw Error(file + ": holds a single model (no 'models:' map); cannot select '" + name +
                  "' - use '" + file + "' alone");
    m = readModel(root, file, "", 0.0);
    m.source = file;
  } else {
    // Root of a multi-model file: rate_hz (default for all), description, models.
    for (const auto& k : mapKeys(root, file, ""))
      if (k != "models" && k != "rate_hz" && k != "description")
        throw keyError(file, k, "unknown key in a multi-model file (expected models, rate_hz, description)");
    const double rate = root["rate_hz"] ? readRate(root["rate_hz"], file, "rate_hz") : 0.0;
    if (name.empty()) {
      if (names.size() != 1)
        throw Error(file + ": holds " + std::to_string(names.size()) +
                    " models; select one as FILE:NAME (available: " + join(names) + ")");
      name = names.front();
    }
    bool found = false;
    for (const auto& n : names) found = found || n == name;
    if (!found)
      throw Error(file + ": no model named '" + name + "' (available: " + join(names) + ")");
    m = readModel(root["models"][name], file, "models." + name + ".", rate);
    m.name = name;
    m.source = file + ":" + name;
  }
  return m;
}

// A value of the wrong type (yaml-cpp's conversion errors, a list or map used
// as a key) is an error naming the file and line, never an internal error.
ImuModel loadImuModel(const std::string& spec) {
  try {
    return loadImuModelImpl(spec);
  } catch (const YAML::Exception& e) {
    throw Error(spec + (e.mark.line >= 0 ? ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) : "") +
                ": " + printable(e.msg, 120) + " (a value or key of the wrong type)");
  }
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

}  // namespace navimpact::stochastic
