// navimpact: which IMU error model is good enough, judged by its actual impact
// on GNSS/INS navigation. Sub-commands register themselves (cmd_*.cpp).
#include <algorithm>
#include <iostream>

#include "cli_common.hpp"
#include "navimpact/core/build_info.hpp"
#include "navimpact/core/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"navimpact — IMU error models judged by their impact on GNSS/INS navigation"};
  std::string version = std::string("navimpact ") + NAVIMPACT_VERSION + "\nbuilt with:";
  for (const auto& [name, ver] : navimpact::buildVersions())
    if (name != "navimpact") version += "\n  " + name + " " + (ver.empty() ? "(unknown)" : ver);
  app.set_version_flag("--version", version);
  app.require_subcommand(1);
  auto& cmds = navimpact::cli::registry();
  std::sort(cmds.begin(), cmds.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  std::function<int()> run;
  for (auto& c : cmds) {
    CLI::App* sub = app.add_subcommand(c.name, c.help);
    auto fn = c.setup(*sub);
    sub->callback([&run, fn]() { run = fn; });
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    return run ? run() : 0;
  } catch (const navimpact::Error& e) {
    std::cerr << "navimpact: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "navimpact: internal error: " << e.what() << "\n";
    return 2;
  }
}
