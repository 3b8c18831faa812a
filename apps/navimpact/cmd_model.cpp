// navimpact model {show,list,convert}: inspect IMU error model files.
//   navimpact model show FILE[:NAME]
//   navimpact model list FILE
//   navimpact model convert FILE[:NAME] --rate HZ [--out FILE.yaml]
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include "cli_common.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/imu_series.hpp"
#include "navimpact/core/output.hpp"
#include "navimpact/stochastic/datasheet.hpp"
#include "navimpact/stochastic/model_file.hpp"
#include "navimpact/stochastic/model_text.hpp"

namespace {

namespace st = navimpact::stochastic;
using navimpact::formatNumber;

struct Opts {
  std::string spec;
  std::string file;
  double rate_hz = 0.0;
  std::string out;
  bool overwrite = false;
};

/// Print one group of axes sharing a model: its text and datasheet figures.
void printGroup(std::ostream& os, const std::string& label, const st::Model& m,
                navimpact::units::Quantity q) {
  os << label << ": " << st::formatTerms(m.terms) << "   [" << navimpact::units::siUnit(q)
     << ", per sample]\n";
  if (m.empty()) return;
  std::istringstream lines(st::formatDatasheet(st::datasheetFigures(m), q));
  std::string l;
  while (std::getline(lines, l)) os << "    " << l << "\n";
}

int runShow(const Opts& o) {
  const st::ImuModel m = st::loadImuModel(o.spec);
  std::cout << "model " << m.source << " (parameters per sample at " << formatNumber(m.rate_hz) << " Hz"
            << ")\n";
  for (int s = 0; s < 2; ++s) {  // gyroscope axes 0..2, accelerometer axes 3..5
    const int a0 = 3 * s;
    const auto q = s == 0 ? navimpact::units::Quantity::AngularRate
                          : navimpact::units::Quantity::SpecificForce;
    const bool same =
        m.axis[a0].terms == m.axis[a0 + 1].terms && m.axis[a0].terms == m.axis[a0 + 2].terms;
    if (same) {
      const std::string label = std::string(navimpact::kChannelNames[a0]) + ", " +
                                navimpact::kChannelNames[a0 + 1] + ", " +
                                navimpact::kChannelNames[a0 + 2];
      printGroup(std::cout, label, m.axis[a0], q);
    } else {
      for (int i = a0; i < a0 + 3; ++i) printGroup(std::cout, navimpact::kChannelNames[i], m.axis[i], q);
    }
  }
  return 0;
}

int runList(const Opts& o) {
  const auto names = st::listModels(o.file);
  if (names.empty()) {
    const st::ImuModel m = st::loadImuModel(o.file);
    std::cout << o.file << ": single model (rate " << formatNumber(m.rate_hz) << " Hz" << ")\n";
    return 0;
  }
  for (const auto& n : names) {
    const st::ImuModel m = st::loadImuModel(o.file + ":" + n);
    std::printf("%-16s gyro: %-14s acc: %-14s (%g Hz)\n", n.c_str(),
                st::formatStructure(m.axis[0]).c_str(), st::formatStructure(m.axis[3]).c_str(),
                m.rate_hz);
  }
  return 0;
}

int runConvert(const Opts& o) {
  std::optional<navimpact::OutputSet> set;
  if (!o.out.empty()) {
    set.emplace(navimpact::OutputSet::singleFile(o.out, navimpact::cli::overwriteMode(o.overwrite)));
    set->mayReplaceAnInput();  // convert --out onto its own model file: read whole first
  }
  const st::ImuModel m = st::loadImuModel(o.spec);
  const st::ImuModel c = st::convertRate(m, o.rate_hz);
  const std::string note = "converted from " + formatNumber(m.rate_hz) + " Hz to " + formatNumber(o.rate_hz) + " Hz";
  // what it writes loads again: the converted terms within the ranges of a model file
  // (a WN sigma of 9e4 at 1 Hz is 9e6 at 10 kHz, beyond any IMU)
  static const char* axes[] = {"gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z"};
  for (int i = 0; i < 6; ++i) {
    try {
      st::validate(c.axis[i]);
    } catch (const navimpact::Error& e) {
      throw navimpact::Error(m.source + ": " + note + ", axis " + axes[i] + ": " + e.what());
    }
  }
  const std::string yaml = st::toYaml(c, "navimpact model convert: " + m.source + ", " + note +
                                             "\n(exact: same noise densities and continuous processes)");
  if (o.out.empty()) {
    std::cout << yaml;
    return 0;
  }
  {
    std::ofstream f(set->stagedFile(), std::ios::binary);
    f << yaml;
    f.close();
    if (!f) throw navimpact::Error(o.out + ": cannot write");
  }
  set->commit();
  std::cout << m.source << ": " << note << ", wrote " << o.out << "\n";
  return 0;
}

navimpact::cli::Registrar reg({"model", "Inspect IMU error model files (show, list, convert)",
                               [](CLI::App& app) -> std::function<int()> {
  auto o = std::make_shared<Opts>();
  app.require_subcommand(1);
  auto* show = app.add_subcommand("show", "Print each axis' model and its datasheet figures");
  show->add_option("model", o->spec, "Model file, FILE or FILE:NAME")->required();
  auto* list = app.add_subcommand("list", "List the named models of a model file");
  list->add_option("file", o->file, "Model file (YAML)")->required();
  auto* conv = app.add_subcommand("convert", "Convert a model exactly to another sampling rate");
  conv->add_option("model", o->spec, "Model file, FILE or FILE:NAME")->required();
  conv->add_option("--rate", o->rate_hz, "New sampling rate [Hz]")->required()->check(
      navimpact::cli::within(navimpact::limits::kImuRateHz));
  conv->add_option("--out", o->out, "Write the converted single-model YAML file here");
  navimpact::cli::addOverwriteFlag(*conv, o->overwrite);
  return [o, show, list, conv]() -> int {
    if (show->parsed()) return runShow(*o);
    if (list->parsed()) return runList(*o);
    if (conv->parsed()) return runConvert(*o);
    return 1;
  };
}});

}  // namespace
