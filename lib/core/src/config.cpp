// The one strict YAML reader (see config.hpp).
#include "navimpact/core/config.hpp"

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "navimpact/core/gz_input.hpp"
#include "navimpact/core/text_io.hpp"
#include "navimpact/core/yaml_load.hpp"

namespace navimpact {

namespace fs = std::filesystem;

struct ConfigNode::Node {
  YAML::Node n;
};

struct ConfigNode::Doc {
  std::string file;
  fs::path dir;
};

namespace {

/// Counts the parser's events and gives up beyond a bound (loadAllYaml).
class EventBudget : public YAML::EventHandler {
 public:
  explicit EventBudget(std::size_t cap) : cap_(cap) {}
  void OnDocumentStart(const YAML::Mark& m) override { tick(m); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& m, YAML::anchor_t) override { tick(m); }
  void OnAlias(const YAML::Mark& m, YAML::anchor_t) override { tick(m); }
  void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t, const std::string&) override { tick(m); }
  void OnSequenceStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    tick(m);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    tick(m);
  }
  void OnMapEnd() override {}

 private:
  void tick(const YAML::Mark& m) {
    if (++n_ > cap_)
      throw YAML::ParserException(m, "the YAML parser (yaml-cpp) does not come to an end on this text; "
                                     "it is malformed near here");
  }
  std::size_t n_ = 0;
  std::size_t cap_;
};

std::string join(const std::string& path, const std::string& k) { return path.empty() ? k : path + "." + k; }

/// What a value looks like, for ", got ...": a scalar quoted and bounded, else its kind.
std::string got(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "nothing";
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a map";
  return "'" + printable(n.Scalar(), 40) + "'";
}

std::string joinNames(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

/// Nodes the key check may visit beyond the text's length: aliases (*NAME) are
/// followed, and a few hundred bytes of nested aliases can stand for billions
/// of nodes; without aliases a document has fewer nodes than bytes.
constexpr std::size_t kMaxAliasNodes = 1000000;
/// Deepest nesting the key check follows: beyond what yaml-cpp parses from
/// text (it refuses ~1000 levels), so only an alias inside its own anchor
/// (`a: &x [*x]`, a node that contains itself) gets there.
constexpr int kMaxDepth = 1200;

/// Control characters are no YAML (c-printable: tab, line feed, carriage return
/// and the printable characters); yaml-cpp drops a NUL silently. Checked in
/// UTF-8 text only: a UTF-16 or UTF-32 file (a zero byte among the first two,
/// or its byte-order mark) is decoded by yaml-cpp itself.
void checkCharacters(const std::string& text, const std::string& file) {
  if (text.size() >= 2 && (text[0] == '\0' || text[1] == '\0' || (text[0] == '\xFF' && text[1] == '\xFE') ||
                           (text[0] == '\xFE' && text[1] == '\xFF')))
    return;
  std::size_t line = 1, col = 1;
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7F)
      throw Error(file + ":" + std::to_string(line) + ":" + std::to_string(col) + ": control character " +
                  printable(std::string(1, ch)) + " (YAML text holds printable characters, tabs and line breaks)");
    if (c == '\n') ++line, col = 1;
    else ++col;
  }
}

/// Every map of the tree: keys are plain names and appear once; no merge key
/// (yaml-cpp does not merge `<<: *NAME`, and a key given both by a merge and
/// directly would need a precedence rule). An alias is checked like the value
/// it stands for, within @p budget nodes in all.
void checkKeys(const YAML::Node& n, const std::string& file, const std::string& path, std::size_t& budget,
               int depth) {
  if (budget == 0)
    throw Error(file + ": aliases (*NAME) expand the document to more than " + std::to_string(kMaxAliasNodes) +
                " nodes beyond its size (nested aliases?)");
  if (depth > kMaxDepth)  // only aliases reach it: yaml-cpp refuses deeper text
    throw keyError(file, path,
                   "nested deeper than " + std::to_string(kMaxDepth) + " levels (an alias *NAME inside its own anchor?)");
  --budget;
  if (n.IsMap()) {
    std::map<std::string, int> seen;
    for (const auto& kv : n) {
      const int line = kv.first.Mark().line + 1;
      if (!kv.first.IsScalar())
        throw Error(file + ":" + std::to_string(line) + ":" + std::to_string(kv.first.Mark().column + 1) + ": key '" +
                    join(path, "?") + "': a key must be a plain name, not a list or a map");
      const std::string k = kv.first.Scalar();
      if (k == "<<")
        throw keyError(file, join(path, k),
                       "merge keys (<<: *NAME) are not supported: write the keys out (a whole value may be an alias *NAME)");
      const auto [it, fresh] = seen.emplace(k, line);
      if (!fresh)
        throw keyError(file, join(path, k),
                       "duplicate key (line " + std::to_string(line) + "; first at line " + std::to_string(it->second) + ")");
      checkKeys(kv.second, file, join(path, k), budget, depth + 1);
    }
  } else if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i) checkKeys(n[i], file, path + "[" + std::to_string(i) + "]", budget, depth + 1);
  }
}

bool scalarDouble(const YAML::Node& v, double& x) {
  if (!v.IsScalar()) return false;
  try {
    x = v.as<double>();
    return true;
  } catch (const YAML::Exception&) {
    return false;
  }
}

std::string rangeText(const limits::Range& r) {
  std::string s = limits::describe(r);
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

/// A number of @p v in @p r, or the one error naming @p key.
double numberOf(const YAML::Node& v, const limits::Range& r, const std::string& file, const std::string& key) {
  double x = 0.0;
  if (!scalarDouble(v, x)) throw keyError(file, key, "must be a number in " + rangeText(r) + ", got " + got(v));
  return limits::check(file, key, x, r);
}

}  // namespace

std::vector<YAML::Node> loadAllYaml(const std::string& text) {
  {
    std::istringstream in(text);
    YAML::Parser parser(in);
    EventBudget budget(4 * text.size() + 64);
    while (parser.HandleNextDocument(budget)) {
    }
  }
  return YAML::LoadAll(text);
}

YAML::Node loadYaml(const std::string& text) {
  std::vector<YAML::Node> docs = loadAllYaml(text);
  return docs.empty() ? YAML::Node() : docs.front();
}

ConfigNode::ConfigNode(std::shared_ptr<const Doc> doc, std::shared_ptr<const Node> node, std::string path)
    : doc_(std::move(doc)), node_(std::move(node)), path_(std::move(path)) {}

std::string ConfigNode::readText(const std::string& file, std::size_t max_bytes) {
  const std::string why = unreadableReason(file);
  if (!why.empty()) throw Error(printable(file, 160) + ": cannot open (" + why + ")");
  std::string text = readFileMaybeGz(file, max_bytes);
  if (const std::string packed = packedFormat(text); !packed.empty())
    throw Error(printable(file, 160) + ": " + packedError(packed));
  return text;
}

ConfigNode ConfigNode::load(const std::string& file) { return parse(readText(file), file); }

ConfigNode ConfigNode::parse(const std::string& text, const std::string& file) {
  checkCharacters(text, file);
  std::vector<YAML::Node> docs;
  try {
    docs = loadAllYaml(text);
  } catch (const YAML::DeepRecursion& e) {
    throw Error(file + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                ": YAML syntax error: nested deeper than " + std::to_string(e.depth()) + " levels");
  } catch (const YAML::Exception& e) {
    throw Error(file + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                ": YAML syntax error: " + printable(e.msg, 120));
  }
  YAML::Node root = docs.empty() ? YAML::Node() : docs.front();
  for (std::size_t i = 1; i < docs.size(); ++i)
    if (docs[i].IsDefined() && !docs[i].IsNull())
      throw Error(file + ":" + std::to_string(docs[i].Mark().line + 1) +
                  ": a second YAML document (after '---'): a file holds one document");
  if (!root.IsDefined() || root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap()) throw Error(file + ": expected a map of keys at the top level, got " + got(root));
  std::size_t budget = kMaxAliasNodes + text.size();
  checkKeys(root, file, "", budget, 0);
  auto doc = std::make_shared<Doc>();
  doc->file = file;
  doc->dir = fs::path(file).parent_path();
  return ConfigNode(doc, std::make_shared<const Node>(Node{root}), "");
}

const std::string& ConfigNode::file() const { return doc_->file; }

std::string ConfigNode::keyPath(const std::string& k) const { return join(path_, k); }

Error ConfigNode::error(const std::string& k, const std::string& what) const {
  return keyError(doc_->file, keyPath(k), what);
}

Error ConfigNode::error(const std::string& what) const {
  return keyError(doc_->file, path_.empty() ? "(top level)" : path_, what);
}

bool ConfigNode::isMap() const { return node_->n.IsMap(); }
bool ConfigNode::isList() const { return node_->n.IsSequence(); }
bool ConfigNode::isScalar() const { return node_->n.IsScalar(); }
bool ConfigNode::isNull() const { return !node_->n.IsDefined() || node_->n.IsNull(); }

void ConfigNode::allowKeys(std::initializer_list<const char*> accepted) const {
  std::vector<std::string> v;
  for (const char* a : accepted) v.emplace_back(a);
  allowKeys(v);
}

void ConfigNode::allowKeys(const std::vector<std::string>& accepted) const {
  std::vector<std::string> sorted = accepted;
  std::sort(sorted.begin(), sorted.end());
  if (!isMap()) throw error("expected a map of keys (" + joinNames(sorted) + "), got " + got(node_->n));
  for (const auto& kv : node_->n) {
    const std::string k = kv.first.Scalar();
    if (!std::binary_search(sorted.begin(), sorted.end(), k))
      throw error(k, "unknown key (accepted: " + joinNames(sorted) + ")");
  }
}

void ConfigNode::requireKeys(std::initializer_list<const char*> keys) const {
  for (const char* k : keys)
    if (!has(k)) throw error(k, "missing (required)");
}

std::vector<std::string> ConfigNode::keys() const {
  std::vector<std::string> out;
  if (!isMap()) return out;
  for (const auto& kv : node_->n) out.push_back(kv.first.Scalar());
  return out;
}

bool ConfigNode::has(const std::string& k) const { return isMap() && static_cast<bool>(node_->n[k]); }

ConfigNode ConfigNode::at(const std::string& k) const {
  return ConfigNode(doc_, std::make_shared<const Node>(Node{node_->n[k]}), keyPath(k));
}

ConfigNode ConfigNode::child(const std::string& k, const std::string& what_for) const {
  if (!has(k)) throw error(k, "missing" + (what_for.empty() ? std::string() : " (" + what_for + ")"));
  return at(k);
}

ConfigNode ConfigNode::map(const std::string& k, const std::string& what_for) const {
  ConfigNode c = child(k, what_for);
  if (!c.isMap()) throw error(k, "must be a map of keys" + (what_for.empty() ? std::string() : " (" + what_for + ")") +
                                     ", got " + got(c.node_->n));
  return c;
}

std::optional<ConfigNode> ConfigNode::optMap(const std::string& k) const {
  if (!has(k)) return std::nullopt;
  return map(k);
}

std::vector<ConfigNode> ConfigNode::items() const {
  std::vector<ConfigNode> out;
  if (!isList()) throw error("must be a list, got " + got(node_->n));
  for (std::size_t i = 0; i < node_->n.size(); ++i)
    out.push_back(ConfigNode(doc_, std::make_shared<const Node>(Node{node_->n[i]}), path_ + "[" + std::to_string(i) + "]"));
  return out;
}

ConfigNode ConfigNode::operator[](const std::string& k) const {
  if (!isMap()) return ConfigNode(doc_, std::make_shared<const Node>(Node{YAML::Node(YAML::NodeType::Undefined)}), keyPath(k));
  return at(k);
}

ConfigNode::operator bool() const { return node_->n.IsDefined(); }

std::string ConfigNode::scalar() const { return isScalar() ? node_->n.Scalar() : std::string(); }

std::vector<ConfigNode> ConfigNode::list(const std::string& k, std::size_t min, std::size_t max,
                                         const std::string& what) const {
  if (!has(k)) {
    if (min > 0) throw error(k, "missing (" + (what.empty() ? "a list" : what) + ")");
    return {};
  }
  const ConfigNode c = at(k);
  const std::size_t n = c.isList() ? node_->n[k].size() : 0;
  if (!c.isList() || n < min || n > max) {
    std::string want = what;
    if (want.empty()) {
      want = "a list";
      if (min > 0 && max != SIZE_MAX) want += " of " + std::to_string(min) + " to " + std::to_string(max) + " items";
      else if (min > 0) want = "a non-empty list";
      else if (max != SIZE_MAX) want += " of at most " + std::to_string(max) + " items";
    }
    throw error(k, "must be " + want + ", got " + (c.isList() ? std::to_string(n) + " items" : got(node_->n[k])));
  }
  return c.items();
}

double ConfigNode::number(const std::string& k, const limits::Range& r, const std::string& what_for) const {
  if (!has(k))
    throw error(k, "missing (a number in " + rangeText(r) + (what_for.empty() ? "" : ": " + what_for) + ")");
  return numberOf(node_->n[k], r, doc_->file, keyPath(k));
}

bool ConfigNode::read(const std::string& k, double& out, const limits::Range& r) const {
  if (!has(k)) return false;
  out = number(k, r);
  return true;
}

bool ConfigNode::read(const std::string& k, std::optional<double>& out, const limits::Range& r) const {
  if (!has(k)) return false;
  out = number(k, r);
  return true;
}

bool ConfigNode::read(const std::string& k, long long& out, long long lo, long long hi) const {
  if (!has(k)) return false;
  const YAML::Node v = node_->n[k];
  const std::string what = "must be an integer in " + std::to_string(lo) + ".." + std::to_string(hi);
  long long x = 0;
  try {
    if (!v.IsScalar()) throw YAML::Exception(YAML::Mark(), "not a scalar");
    x = v.as<long long>();
  } catch (const YAML::Exception&) {
    throw error(k, what + ", got " + got(v));
  }
  if (x < lo || x > hi) throw error(k, what + ", got " + std::to_string(x));
  out = x;
  return true;
}

bool ConfigNode::read(const std::string& k, int& out, long long lo, long long hi) const {
  long long v = out;
  if (!read(k, v, lo, hi)) return false;
  out = static_cast<int>(v);
  return true;
}

bool ConfigNode::read(const std::string& k, std::size_t& out, long long lo, long long hi) const {
  long long v = static_cast<long long>(out);
  if (!read(k, v, std::max(0LL, lo), hi)) return false;
  out = static_cast<std::size_t>(v);
  return true;
}

bool ConfigNode::readSeed(const std::string& k, std::uint64_t& out) const {
  if (!has(k)) return false;
  const YAML::Node v = node_->n[k];
  try {
    if (!v.IsScalar()) throw YAML::Exception(YAML::Mark(), "not a scalar");
    out = v.as<std::uint64_t>();
  } catch (const YAML::Exception&) {
    throw error(k, "must be an integer seed in 0.." + std::to_string(std::numeric_limits<std::uint64_t>::max()) +
                       ", got " + got(v));
  }
  return true;
}

bool ConfigNode::read(const std::string& k, bool& out) const {
  if (!has(k)) return false;
  out = at(k).asBool();
  return true;
}

bool ConfigNode::read(const std::string& k, std::string& out) const {
  if (!has(k)) return false;
  out = at(k).asText();
  return true;
}

std::string ConfigNode::text(const std::string& k, const std::string& what_for, bool non_empty) const {
  if (!has(k)) throw error(k, "missing" + (what_for.empty() ? std::string() : " (" + what_for + ")"));
  std::string s;
  read(k, s);
  if (non_empty && s.empty()) throw error(k, "must be a non-empty text");
  return s;
}

int ConfigNode::readChoice(const std::string& k, std::string& out, const std::vector<std::string>& choices) const {
  if (!has(k)) return -1;
  const YAML::Node v = node_->n[k];
  if (v.IsScalar())
    for (std::size_t i = 0; i < choices.size(); ++i)
      if (v.Scalar() == choices[i]) {
        out = choices[i];
        return static_cast<int>(i);
      }
  throw error(k, "must be one of " + joinNames(choices) + ", got " + got(v));
}

bool ConfigNode::read(const std::string& k, Eigen::Vector3d& out, const limits::Range& each) const {
  std::vector<double> v;
  if (!read(k, v, each, 3, 3)) return false;
  out = Eigen::Vector3d(v[0], v[1], v[2]);
  return true;
}

bool ConfigNode::read(const std::string& k, std::vector<double>& out, const limits::Range& each, std::size_t min,
                      std::size_t max) const {
  if (!has(k)) return false;
  std::string what = "a list of ";
  if (min == max) what += std::to_string(min) + " numbers";
  else if (max != SIZE_MAX) what += std::to_string(min) + " to " + std::to_string(max) + " numbers";
  else what += "numbers";
  what += " in " + rangeText(each);
  std::vector<double> xs;
  for (const auto& item : list(k, min, max, what)) xs.push_back(item.asNumber(each));
  out = xs;
  return true;
}

bool ConfigNode::read(const std::string& k, std::vector<std::string>& out, std::size_t min, std::size_t max) const {
  if (!has(k)) return false;
  std::vector<std::string> xs;
  for (const auto& item : list(k, min, max)) xs.push_back(item.asText());
  out = xs;
  return true;
}

std::string ConfigNode::resolve(const std::string& p) const {
  if (p.empty() || fs::path(p).is_absolute() || doc_->dir.empty()) return p;
  return (doc_->dir / p).lexically_normal().string();
}

/// @p path (named by key @p k) if it can be read, else the one error naming the key.
std::string ConfigNode::checkedInput(const std::string& k, const std::string& path) const {
  const std::string why = unreadableReason(path);
  if (!why.empty()) throw error(k, "cannot open '" + printable(path, 160) + "' (" + why + ")");
  return path;
}

std::string ConfigNode::inputFile(const std::string& k, const std::string& what_for) const {
  const std::string p = text(k, what_for);
  if (p.empty()) throw error(k, "must be a non-empty path (" + what_for + ")");
  return checkedInput(k, resolve(p));
}

std::string ConfigNode::modelRef(const std::string& k) const {
  std::string spec;
  read(k, spec);
  if (spec.empty() && has(k)) throw error(k, "must be a model FILE[:NAME], got ''");
  if (spec.empty()) return spec;
  if (unreadableReason(resolve(spec)).empty()) return resolve(spec);  // the whole text names a file
  const auto colon = spec.rfind(':');
  if (colon == std::string::npos || colon == 0) return checkedInput(k, resolve(spec));
  const std::string name = spec.substr(colon + 1);
  if (name.find('/') != std::string::npos) return checkedInput(k, resolve(spec));
  return checkedInput(k, resolve(spec.substr(0, colon))) + ":" + name;
}

double ConfigNode::asNumber(const limits::Range& r) const {
  return numberOf(node_->n, r, doc_->file, path_);
}

bool ConfigNode::asBool() const {
  const YAML::Node& v = node_->n;
  try {
    if (!v.IsScalar()) throw YAML::Exception(YAML::Mark(), "not a scalar");
    return v.as<bool>();
  } catch (const YAML::Exception&) {
    throw error("must be true or false, got " + got(v));
  }
}

std::string ConfigNode::asText() const {
  const YAML::Node& v = node_->n;
  if (!v.IsScalar()) throw error("must be a text, got " + got(v));
  return v.Scalar();
}

}  // namespace navimpact
