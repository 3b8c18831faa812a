// The registry of process kinds: process_kinds.def lists them, each one's
// definition lives in processes/<name>.cpp.
#include <algorithm>
#include <cctype>

#include "kind.hpp"
#include "navimpact/core/error.hpp"

namespace navimpact::stochastic {

namespace detail {

#define NAVIMPACT_PROCESS_KIND(NAME, DOC) const KindDef& kind##NAME();
#include "navimpact/stochastic/process_kinds.def"

namespace {

const std::vector<const KindDef*>& defs() {
  static const std::vector<const KindDef*> d = {
#define NAVIMPACT_PROCESS_KIND(NAME, DOC) &kind##NAME(),
#include "navimpact/stochastic/process_kinds.def"
  };
  return d;
}

}  // namespace

bool iequals(const std::string& a, const char* b) {
  std::size_t i = 0;
  for (; i < a.size() && b[i]; ++i)
    if (std::toupper(static_cast<unsigned char>(a[i])) !=
        std::toupper(static_cast<unsigned char>(b[i])))
      return false;
  return i == a.size() && b[i] == '\0';
}

const KindDef& kindDef(ProcessKind k) {
  const auto i = static_cast<std::size_t>(k);
  if (i >= defs().size()) throw Error("internal: unknown process kind " + std::to_string(i));
  const KindDef& d = *defs()[i];
  if (d.info().kind != k)
    throw Error("internal: process kind " + std::string(d.info().name) +
                " is registered out of the order of process_kinds.def");
  return d;
}

}  // namespace detail

const KindInfo& kindInfo(ProcessKind k) { return detail::kindDef(k).info(); }

const char* kindName(ProcessKind k) {
  const auto i = static_cast<std::size_t>(k);
  if (i >= allKinds().size()) return "?";
  return kindInfo(k).name;
}

const char* kindSummary(ProcessKind k) {
  static const char* const docs[] = {
#define NAVIMPACT_PROCESS_KIND(NAME, DOC) DOC,
#include "navimpact/stochastic/process_kinds.def"
  };
  const auto i = static_cast<std::size_t>(k);
  return i < allKinds().size() ? docs[i] : "?";
}

const std::vector<ProcessKind>& allKinds() {
  static const std::vector<ProcessKind> all = {
#define NAVIMPACT_PROCESS_KIND(NAME, DOC) ProcessKind::NAME,
#include "navimpact/stochastic/process_kinds.def"
  };
  return all;
}

std::optional<ProcessKind> kindFromName(const std::string& name) {
  for (ProcessKind k : allKinds()) {
    const KindInfo& i = kindInfo(k);
    if (detail::iequals(name, i.name)) return k;
    for (const AliasInfo& a : i.aliases)
      if (detail::iequals(name, a.name)) return k;
  }
  return std::nullopt;
}

std::pair<double, double> paramRange(ProcessKind k, std::size_t i, double rate_hz,
                                     double duration_s) {
  const KindInfo& info = kindInfo(k);
  if (i >= info.params.size())
    throw Error(std::string(info.name) + " has no parameter " + std::to_string(i + 1));
  return info.params[i].range(rate_hz, duration_s);
}

}  // namespace navimpact::stochastic
