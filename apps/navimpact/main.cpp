// navimpact: which IMU error model is good enough, judged by its actual impact
// on GNSS/INS navigation. Sub-commands register themselves (cmd_*.cpp).
//
// Every failure is reported here, at the edge, as ONE line of at most ~300
// characters: `navimpact: FILE[:LINE|: entry N|: key K]: what is wrong (what is
// accepted)`, with a documented exit code (README, "Exit codes"):
//   0 success; 1 bad input, configuration or a refused budget (navimpact::Error,
//   and parse errors of yaml-cpp); 2 command line not understood (CLI11);
//   3 out of memory; 4 internal error (a bug: please report it).
#include <signal.h>

#include <algorithm>
#include <iostream>
#include <new>
#include <string>

#include "cli_common.hpp"
#include "navimpact/core/build_info.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/output.hpp"

namespace {

enum ExitCode : int { kOk = 0, kBadInput = 1, kUsage = 2, kOutOfMemory = 3, kInternal = 4 };

int fail(int code, const std::string& msg) {
  std::cout.flush();
  std::cerr << navimpact::oneLine("navimpact: " + msg) << "\n";
  return code;
}

/// SIGINT, SIGTERM, SIGHUP: remove the staging folders of the live jobs, then
/// die of the signal as before (exit status 128 + signal for the shell).
extern "C" void onTerminate(int sig) {
  navimpact::removeLiveStaging();
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

void cleanUpOnTermination() {
  struct sigaction sa {};
  sa.sa_handler = onTerminate;
  sigemptyset(&sa.sa_mask);  // the three wait for one another: one removal at a time
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&sa.sa_mask, sig);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    // a signal the caller ignores (nohup) stays ignored
    if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    ::sigaction(sig, &sa, nullptr);
  }
}

/// The input being processed when a non-navimpact exception left it, or the command.
std::string subject(const std::string& command) {
  const std::string f = navimpact::InputScope::failedInput();
  if (!f.empty()) return f;
  // the command without the program name ("navimpact: emulate: ...", not "navimpact: navimpact emulate: ...")
  const std::string program = "navimpact ";
  if (command.rfind(program, 0) == 0) return command.substr(program.size());
  return command.empty() ? std::string("navimpact") : command;
}

/// yaml-cpp's "yaml-cpp: error at line L, column C: MSG" as "L:C: MSG" (1-based
/// line and column, as yaml-cpp prints them), or "" when @p what is not one.
std::string yamlLocation(const std::string& what) {
  const std::string pre = "yaml-cpp: error at line ";
  if (what.rfind(pre, 0) != 0) return {};
  unsigned line = 0, col = 0;
  int used = 0;
  if (std::sscanf(what.c_str() + pre.size(), "%u, column %u: %n", &line, &col, &used) < 2 || used == 0)
    return {};
  return std::to_string(line) + ":" + std::to_string(col) + ": " + what.substr(pre.size() + used);
}

}  // namespace

int main(int argc, char** argv) {
  cleanUpOnTermination();
  CLI::App app{"navimpact — IMU error models judged by their impact on GNSS/INS navigation"};
  std::string version = std::string("navimpact ") + NAVIMPACT_VERSION + "\nbuilt with:";
  for (const auto& [name, ver] : navimpact::buildVersions())
    if (name != "navimpact") version += "\n  " + name + " " + (ver.empty() ? "(unknown)" : ver);
  app.set_version_flag("--version", version);
  app.require_subcommand(1);
  app.footer("Exit codes: 0 success, 1 bad input or configuration, 2 command line not understood, "
             "3 out of memory, 4 internal error.");
  auto& cmds = navimpact::cli::registry();
  std::sort(cmds.begin(), cmds.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  std::function<int()> run;
  for (auto& c : cmds) {
    CLI::App* sub = app.add_subcommand(c.name, c.help);
    auto fn = c.setup(*sub);
    sub->callback([&run, fn]() { run = fn; });
  }
  std::string command;  // "navimpact SUB [SUBSUB]" as far as it was parsed
  auto commandName = [&app]() {
    std::string name = "navimpact";
    for (const CLI::App* a = &app;;) {
      const auto subs = a->get_subcommands();
      if (subs.empty()) break;
      a = subs.front();
      name += " " + a->get_name();
    }
    return name;
  };
  if (argc > 1 && argv[1][0] != '-') {  // CLI11 would only say "A subcommand is required"
    std::string names;
    bool known = false;
    for (const auto& c : cmds) {
      names += (names.empty() ? "" : ", ") + c.name;
      known = known || c.name == argv[1];
    }
    if (!known)
      return fail(kUsage, "unknown command '" + navimpact::printable(argv[1], 40) + "' (commands: " + names + ")");
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    return fail(kUsage, std::string(e.what()) + " (see '" + commandName() + " --help')");
  }
  command = commandName();
  try {
    return run ? run() : kOk;
  } catch (const navimpact::Error& e) {
    return fail(kBadInput, e.what());
  } catch (const std::bad_alloc&) {
    return fail(kOutOfMemory, subject(command) +
                                  ": out of memory while processing it (reduce the input or the configured work)");
  } catch (const std::exception& e) {
    const std::string what = e.what();
    if (const std::string y = yamlLocation(what); !y.empty())  // a YAML file no reader translated
      return fail(kBadInput, subject(command) + ":" + y);
    return fail(kInternal, subject(command) + ": internal error: " + what + " (please report it)");
  } catch (...) {
    return fail(kInternal, subject(command) + ": internal error (unknown exception; please report it)");
  }
}
