// The text form of models and structures: a small hand-written recursive
// descent parser with 1-based character positions in every error message.
#include "navimpact/stochastic/model_text.hpp"

#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "kind.hpp"
#include "navimpact/core/error.hpp"
#include "navimpact/core/text_io.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/stochastic/process_kind.hpp"

namespace navimpact::stochastic {

namespace {

/// One accepted process name: a kind's own name or one of its aliases,
/// with its keys in the canonical (print) order.
struct TermSpec {
  const detail::KindDef* def;
  int alias;  ///< -1: the kind's own name and parameters; else the alias index
  const char* name;
  std::vector<const char*> keys;
};

/// Every accepted name: each kind (process_kinds.def order) followed by its aliases.
const std::vector<TermSpec>& specs() {
  static const std::vector<TermSpec> all = [] {
    std::vector<TermSpec> v;
    for (ProcessKind k : allKinds()) {
      const detail::KindDef& d = detail::kindDef(k);
      std::vector<const char*> keys;
      for (const ParamInfo& p : d.info().params) keys.push_back(p.key);
      v.push_back({&d, -1, d.info().name, keys});
      for (std::size_t a = 0; a < d.info().aliases.size(); ++a)
        v.push_back({&d, static_cast<int>(a), d.info().aliases[a].name, d.info().aliases[a].keys});
    }
    return v;
  }();
  return all;
}

std::string namesList() {
  std::string s;
  for (const auto& sp : specs()) {
    if (!s.empty()) s += ", ";
    s += sp.name;
  }
  return s;
}

/// Cursor over the text; positions reported 1-based.
class Parser {
 public:
  Parser(const std::string& text, const char* what) : s_(text), what_(what) {}

  void skipWs() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  bool atEnd() {
    skipWs();
    return i_ >= s_.size();
  }
  char peek() {
    skipWs();
    return i_ < s_.size() ? s_[i_] : '\0';
  }
  std::size_t pos() const { return i_; }

  /// Description of what is at the cursor, for "found Y".
  std::string found() {
    skipWs();
    if (i_ >= s_.size()) return "end of text";
    std::size_t j = i_;
    if (std::isalnum(static_cast<unsigned char>(s_[j])) || s_[j] == '_' || s_[j] == '.' ||
        s_[j] == '-' || s_[j] == '+') {
      ++j;
      while (j < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[j])) || s_[j] == '_' ||
                               s_[j] == '.'))
        ++j;
    } else {
      ++j;
    }
    return "'" + printable(std::string_view(s_).substr(i_, j - i_), 40) + "'";
  }

  [[noreturn]] void fail(std::size_t at, const std::string& expected, const std::string& found) {
    throw Error(std::string(what_) + " '" + printable(s_, 80) + "': at position " + std::to_string(at + 1) +
                ": expected " + expected + ", found " + found);
  }
  [[noreturn]] void failHere(const std::string& expected) {
    skipWs();
    const std::string f = found();
    fail(i_, expected, f);
  }

  void expect(char c, const std::string& expected) {
    if (peek() != c) failHere(expected);
    ++i_;
  }

  /// Identifier [A-Za-z_][A-Za-z0-9_]*; empty if none at the cursor.
  std::string identifier() {
    skipWs();
    std::size_t j = i_;
    if (j < s_.size() && (std::isalpha(static_cast<unsigned char>(s_[j])) || s_[j] == '_')) {
      ++j;
      while (j < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[j])) || s_[j] == '_'))
        ++j;
    }
    std::string id = s_.substr(i_, j - i_);
    i_ = j;
    return id;
  }

  /// A finite decimal number; the whole token up to a delimiter must parse.
  double number() {
    skipWs();
    const std::size_t start = i_;
    std::size_t j = i_;
    while (j < s_.size() && !std::isspace(static_cast<unsigned char>(s_[j])) && s_[j] != ',' &&
           s_[j] != ')' && s_[j] != '(' && s_[j] != '=') {
      // '+' separates terms unless it is an exponent or leading sign.
      if (s_[j] == '+' && j > start && s_[j - 1] != 'e' && s_[j - 1] != 'E') break;
      ++j;
    }
    const std::string tok = s_.substr(start, j - start);
    if (tok.empty()) failHere("a number");
    // decimal only (std::from_chars): strtod also took hex, so sigma=0x10 was 16
    double v = 0.0;
    if (!parseDouble(tok, v)) fail(start, "a number", "'" + printable(tok, 40) + "'");
    if (!std::isfinite(v)) fail(start, "a finite number", "'" + printable(tok, 40) + "'");
    i_ = j;
    return v;
  }

  const std::string& text() const { return s_; }
  void advanceTo(std::size_t j) { i_ = j; }

 private:
  const std::string& s_;
  const char* what_;
  std::size_t i_ = 0;
};

Process parseTerm(Parser& P, double rate_hz) {
  P.skipWs();
  const std::size_t name_pos = P.pos();
  const std::string name = P.identifier();
  if (name.empty()) P.failHere("a process name (" + namesList() + ")");
  const TermSpec* spec = nullptr;
  for (const auto& sp : specs())
    if (detail::iequals(name, sp.name)) spec = &sp;
  if (!spec) P.fail(name_pos, "a process name (" + namesList() + ")", "'" + printable(name, 40) + "'");
  const int nkeys = static_cast<int>(spec->keys.size());

  std::string keylist;
  for (int k = 0; k < nkeys; ++k) keylist += std::string(k ? ", " : "") + spec->keys[k];

  P.expect('(', "'(' after " + std::string(spec->name));
  std::vector<std::optional<double>> values(spec->keys.size());
  std::vector<std::size_t> value_pos(spec->keys.size(), 0);
  bool first = true;
  while (true) {
    if (P.peek() == ')') {
      if (!first) P.failHere("a key (" + keylist + ")");  // trailing comma
      break;
    }
    P.skipWs();
    const std::size_t key_pos = P.pos();
    const std::string key = P.identifier();
    if (key.empty()) P.failHere("a key (" + keylist + ") of " + spec->name);
    int idx = -1;
    for (int k = 0; k < nkeys; ++k)
      if (detail::iequals(key, spec->keys[k])) idx = k;
    if (idx < 0)
      P.fail(key_pos, "a key of " + std::string(spec->name) + " (" + keylist + ")",
             "unknown key '" + printable(key, 40) + "'");
    if (values[idx])
      P.fail(key_pos, "each key once (" + keylist + ")",
             "duplicate key '" + std::string(spec->keys[idx]) + "'");
    P.expect('=', "'=' after " + std::string(spec->keys[idx]));
    P.skipWs();
    value_pos[idx] = P.pos();
    values[idx] = P.number();
    first = false;
    const char c = P.peek();
    if (c == ',') {
      P.expect(',', "','");
      continue;
    }
    if (c == ')') break;
    P.failHere("',' or ')'");
  }
  const std::size_t close_pos = P.pos();
  P.expect(')', "')'");
  for (int k = 0; k < nkeys; ++k)
    if (!values[k])
      P.fail(close_pos, "key '" + std::string(spec->keys[k]) + "' of " + spec->name + "(" +
                            keylist + ")",
             "')'");

  std::vector<double> v(values.size());
  for (std::size_t k = 0; k < v.size(); ++k) v[k] = *values[k];
  if (spec->alias >= 0) {
    // Another input form of the kind (AR1 for GM), converted by the kind.
    try {
      return spec->def->fromAlias(static_cast<std::size_t>(spec->alias), v.data(), rate_hz);
    } catch (const detail::AliasValueError& e) {
      P.fail(e.key >= 0 ? value_pos[static_cast<std::size_t>(e.key)] : name_pos, e.expected, e.found);
    }
  }
  Process p;
  p.kind = spec->def->info().kind;
  for (std::size_t k = 0; k < v.size(); ++k) p.*(spec->def->info().params[k].field) = v[k];
  return p;
}


}  // namespace

std::vector<Process> parseTerms(const std::string& text, double rate_hz) {
  Parser P(text, "model");
  std::vector<Process> terms;
  if (P.atEnd()) P.failHere("'none' or a process term");
  {
    // "none" (alone) = no error.
    Parser Q(text, "model");
    const std::string id = Q.identifier();
    if (detail::iequals(id, "none")) {
      if (!Q.atEnd()) Q.failHere("end of text after 'none'");
      return terms;
    }
  }
  while (true) {
    // a model has a handful of terms: 300,000 WN terms made emulate hold 2.5 GB
    if (terms.size() == static_cast<std::size_t>(limits::kMaxTermsPerModel))
      P.fail(0, "at most " + std::to_string(limits::kMaxTermsPerModel) + " terms in one model",
             "more (a model has a handful)");
    terms.push_back(parseTerm(P, rate_hz));
    if (P.atEnd()) break;
    if (P.peek() != '+') P.failHere("'+' or end of text");
    P.expect('+', "'+'");
  }
  return terms;
}

Model parseModel(const std::string& text, double rate_hz) {
  Model m;
  m.rate_hz = rate_hz;
  m.terms = parseTerms(text, rate_hz);
  return m;
}

std::string formatTerms(const std::vector<Process>& terms, int digits) {
  if (terms.empty()) return "none";
  std::string s;
  for (const auto& p : terms) {
    if (!s.empty()) s += " + ";
    const KindInfo& info = kindInfo(p.kind);
    s += info.name;
    s += "(";
    for (std::size_t k = 0; k < info.params.size(); ++k)
      s += std::string(k ? ", " : "") + info.params[k].key + "=" +
           // digits >= 17: exact (formatExact: the lowest precision 15..17 that reads back)
           (digits >= 17 ? formatExact(p.*info.params[k].field) : formatNumber(p.*info.params[k].field, digits));
    s += ")";
  }
  return s;
}

std::vector<ProcessKind> parseStructure(const std::string& spec) {
  Parser P(spec, "structure");
  std::vector<ProcessKind> kinds;
  if (P.atEnd()) P.failHere("a process name (" + namesList() + ")");
  while (true) {
    // Optional repetition count: "3GM" or "3*GM".
    int count = 1;
    P.skipWs();
    if (std::isdigit(static_cast<unsigned char>(P.peek()))) {
      const std::size_t at = P.pos();
      std::size_t j = at;
      const std::string& s = P.text();
      while (j < s.size() && std::isdigit(static_cast<unsigned char>(s[j]))) ++j;
      count = std::atoi(s.substr(at, j - at).c_str());
      if (count < 1 || count > 16 || j - at > 2)
        P.fail(at, "a repetition count 1..16", "'" + printable(std::string_view(s).substr(at, j - at), 40) + "'");
      P.advanceTo(j);
      if (P.peek() == '*') P.expect('*', "'*'");
    }
    P.skipWs();
    const std::size_t at = P.pos();
    const std::string name = P.identifier();
    if (name.empty()) P.failHere("a process name (" + namesList() + ")");
    const std::optional<ProcessKind> kind = kindFromName(name);  // aliases too: AR1 is a GM
    if (!kind) P.fail(at, "a process name (" + namesList() + ")", "'" + name + "'");
    const ProcessKind k = *kind;
    // Tolerate the R-style empty call "GM()".
    if (P.peek() == '(') {
      P.expect('(', "'('");
      P.expect(')', "')' (a structure has no parameters)");
    }
    for (int c = 0; c < count; ++c) kinds.push_back(k);
    if (P.atEnd()) break;
    P.expect('+', "'+' or end of text");
  }
  return kinds;
}

std::string formatStructure(const Model& m) { return formatStructure(m.structure()); }

std::string formatStructure(const std::vector<ProcessKind>& kinds) {
  if (kinds.empty()) return "none";
  std::string s;
  for (auto k : kinds) {
    if (!s.empty()) s += "+";
    s += kindName(k);
  }
  return s;
}

}  // namespace navimpact::stochastic
