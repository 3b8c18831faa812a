/**
 * @file config.hpp
 * @brief The one strict reader of navimpact's YAML files (configurations,
 *        scenarios, model files, import manifests).
 *
 * Each configuration struct loads itself from a ConfigNode beside its
 * definition (`loadFrom(const ConfigNode&)`, in the manner of MOLA's
 * NavStateFuseParams), reading each key with one call that names the key, its
 * type, its unit and its accepted range (lib/core/limits.hpp). Every failure is
 * one line in one format, "FILE: key 'DOTTED.KEY': what is wrong":
 * @code
 *   study.yaml: key 'filter.propagate_every': must be an integer in 1..1000, got 0
 *   study.yaml: key 'gnss.sigma_pos_h_m': must be in (0, 10000] m, got 0
 *   study.yaml: key 'gnss.sigma_pos_h_m': must be a number in (0, 10000] m, got 'two'
 *   study.yaml: key 'gnss.seeed': unknown key (accepted: lever_arm_B_m, rate_hz, ...)
 *   study.yaml: key 'gnss': duplicate key (line 14; first at line 3)
 *   study.yaml:3:7: YAML syntax error: ...
 * @endcode
 * Duplicate keys (which yaml-cpp would silently resolve to the first) and keys
 * that are not plain names are errors anywhere in a file, read or not; they
 * are found when the file is parsed. Unknown keys are errors where a reader
 * states the keys it accepts (allowKeys()).
 *
 * Units: SI inside; every numeric key carries its unit in its name
 * (`rate_hz`, `duration_s`, `sigma_pos_h_m`, `yaw_deg`) and its range names
 * the unit in messages.
 */
#pragma once

#include <cstdint>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "navimpact/core/error.hpp"
#include "navimpact/core/limits.hpp"

namespace navimpact {

/**
 * A node (map, list or value) of a YAML file being read, with its dotted path
 * ("gnss", "candidates[2]", "sweep.outage"). Cheap to copy.
 */
class ConfigNode {
 public:
  /// Read and parse a YAML file (plain or gzip, at most 64 MiB).
  /// @throws navimpact::Error "FILE: cannot open (REASON)", "FILE:LINE:COLUMN: YAML syntax error: ...",
  ///         a duplicate or non-name key anywhere, or a top level that is not a map.
  static ConfigNode load(const std::string& file);
  /// The text of a YAML file (plain or gzip, at most @p max_bytes) for parse():
  /// "FILE: cannot open (REASON)" when it cannot be read; a FIFO or device is
  /// refused (its reading could block or never end).
  static std::string readText(const std::string& file, std::size_t max_bytes = std::size_t(64) << 20);
  /// Parse YAML @p text that came from @p file (named in messages; paths are relative to its folder).
  /// An empty text is an empty map. Refused: control characters (a NUL yaml-cpp would drop
  /// silently), a second document after '---' (yaml-cpp would ignore it), aliases that
  /// nest without end (an alias inside its own anchor).
  static ConfigNode parse(const std::string& text, const std::string& file);

  /// The file as the user named it.
  const std::string& file() const;
  /// Dotted path of this node ("" for the top level).
  const std::string& path() const { return path_; }
  /// Dotted path of child key @p k.
  std::string keyPath(const std::string& k) const;
  /// "FILE: key 'PATH.K': what".
  Error error(const std::string& k, const std::string& what) const;
  /// "FILE: key 'PATH': what" about this node itself ("(top level)" for the root).
  Error error(const std::string& what) const;

  // ---- structure --------------------------------------------------------
  bool isMap() const;
  bool isList() const;
  bool isScalar() const;
  /// True when this node's value is empty (`key:` or `key: ~`).
  bool isNull() const;
  /// @throws "expected a map of keys (KEYS), got ..." unless this node is a map.
  /// Then every key not in @p accepted is "unknown key (accepted: a, b, c)" (sorted).
  void allowKeys(std::initializer_list<const char*> accepted) const;
  void allowKeys(const std::vector<std::string>& accepted) const;
  /// @throws "missing (required)" for the first of @p keys that is absent.
  void requireKeys(std::initializer_list<const char*> keys) const;
  /// The keys of this map in file order.
  std::vector<std::string> keys() const;
  /// True when key @p k is present (a `key:` with no value counts as present).
  bool has(const std::string& k) const;
  /// The node under key @p k, whatever it holds. @throws "missing (WHAT_FOR)" when absent.
  ConfigNode child(const std::string& k, const std::string& what_for = "") const;
  /// The map under key @p k. @throws when missing (naming @p what_for) or not a map.
  ConfigNode map(const std::string& k, const std::string& what_for = "") const;
  /// The map under key @p k when present.
  std::optional<ConfigNode> optMap(const std::string& k) const;
  /// The items of the list under key @p k (paths "k[0]", "k[1]", ...); empty when absent.
  /// @throws when it is not a list or has fewer than @p min or more than @p max items.
  std::vector<ConfigNode> list(const std::string& k, std::size_t min = 0, std::size_t max = SIZE_MAX,
                               const std::string& what = "") const;
  /// The items of this node, which must be a list.
  std::vector<ConfigNode> items() const;
  /// The node under key @p k, which may be absent (then `!node`): for readers
  /// that decide by what is present.
  ConfigNode operator[](const std::string& k) const;
  /// True when this node is present in the file (a `key:` without value counts).
  explicit operator bool() const;
  /// The text of a scalar ("" for a list, a map or an absent node).
  std::string scalar() const;

  // ---- values of keys of this map ---------------------------------------
  // The optional forms leave @p out unchanged when the key is absent and
  // return whether it was present; the required forms throw "missing (...)".

  /// Required number in @p r.
  double number(const std::string& k, const limits::Range& r, const std::string& what_for = "") const;
  bool read(const std::string& k, double& out, const limits::Range& r) const;
  bool read(const std::string& k, std::optional<double>& out, const limits::Range& r) const;
  /// An integer in lo..hi (a fractional or out-of-range value is refused).
  bool read(const std::string& k, int& out, long long lo, long long hi) const;
  bool read(const std::string& k, long long& out, long long lo, long long hi) const;
  bool read(const std::string& k, std::size_t& out, long long lo, long long hi) const;
  /// A seed: any integer 0 .. 2^64 - 1.
  bool readSeed(const std::string& k, std::uint64_t& out) const;
  /// true/false (also yes/no, on/off).
  bool read(const std::string& k, bool& out) const;
  /// Any scalar as text.
  bool read(const std::string& k, std::string& out) const;
  /// Required text (non-empty when @p non_empty).
  std::string text(const std::string& k, const std::string& what_for = "", bool non_empty = false) const;
  /// One of @p choices (case-sensitive); returns its index or -1 when absent.
  int readChoice(const std::string& k, std::string& out, const std::vector<std::string>& choices) const;
  /// [x, y, z], each in @p each (errors name "k[i]").
  bool read(const std::string& k, Eigen::Vector3d& out, const limits::Range& each) const;
  /// A list of @p min..@p max numbers, each in @p each (errors name "k[i]").
  bool read(const std::string& k, std::vector<double>& out, const limits::Range& each, std::size_t min = 0,
            std::size_t max = SIZE_MAX) const;
  /// A list of @p min..@p max texts.
  bool read(const std::string& k, std::vector<std::string>& out, std::size_t min = 0,
            std::size_t max = SIZE_MAX) const;
  /// The input file named by key @p k (@p what_for says what it holds, for
  /// "missing (WHAT_FOR)"), resolved against this file's folder when relative
  /// and checked when the configuration is read, so that a file that cannot be
  /// read is named with the configuration and the key:
  /// "FILE: key 'K': cannot open 'PATH' (No such file or directory)" (or
  /// "Permission denied", "Is a directory", "not a regular file").
  std::string inputFile(const std::string& k, const std::string& what_for) const;
  /// A model reference FILE[:NAME], FILE resolved against the file's folder
  /// when relative and checked like inputFile() ("" when absent; an empty text
  /// is an error, not the default). A colon at
  /// position 0 or followed by a name containing '/' belongs to the path, and
  /// so does every colon when the whole text names a file.
  std::string modelRef(const std::string& k) const;
  /// @p p resolved against the file's folder when relative.
  std::string resolve(const std::string& p) const;

  // ---- the value of this node itself (a list item) ----------------------
  double asNumber(const limits::Range& r) const;
  bool asBool() const;
  std::string asText() const;

  struct Doc;   ///< the file (internal)
  struct Node;  ///< a YAML::Node, kept out of this header (internal)

 private:
  ConfigNode(std::shared_ptr<const Doc> doc, std::shared_ptr<const Node> node, std::string path);
  ConfigNode at(const std::string& k) const;
  std::string checkedInput(const std::string& k, const std::string& path) const;
  std::shared_ptr<const Doc> doc_;
  std::shared_ptr<const Node> node_;
  std::string path_;
};

/// The configuration file @p path read by @p Config::loadFrom(ConfigNode),
/// with the path kept in its member @p file; an exception other than
/// navimpact::Error leaving the read names the file (InputScope).
template <class Config, class... Args>
Config loadConfigFile(const std::string& path, std::string Config::*file, const Args&... args) {
  InputScope scope(path);
  Config c;
  c.*file = path;
  c.loadFrom(ConfigNode::load(path), args...);
  return c;
}

}  // namespace navimpact
