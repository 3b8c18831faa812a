/**
 * @file error.hpp
 * @brief The one exception type of navimpact's libraries.
 *
 * Library code never prints and never exits: it throws navimpact::Error with a
 * message that names the place (file, line, column, key) and what was expected.
 * Applications catch it, print one line and return a non-zero exit code.
 */
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace navimpact {

/// Error with a human-readable, one-line message naming where it happened.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/**
 * Build an error located in a text file.
 * @param[in] file  path of the file as the user gave it.
 * @param[in] line  1-based line number, or 0 when not applicable.
 * @param[in] what  what is wrong and, where it helps, what was expected.
 * @return an Error whose message reads "FILE:LINE: WHAT".
 */
Error fileError(const std::string& file, std::size_t line, const std::string& what);

/**
 * Build an error about a configuration key.
 * @param[in] file  configuration file (may be empty for command-line values).
 * @param[in] key   dotted path of the key, e.g. "gnss.sigma_pos_h_m".
 * @param[in] what  what is wrong.
 */
Error keyError(const std::string& file, const std::string& key, const std::string& what);

/// The place keyError() names: "FILE: key 'KEY'" ("key 'KEY'" without a file).
std::string keyPlace(const std::string& file, const std::string& key);

/**
 * Raw input made safe to echo in a message: control characters, bytes that are
 * not valid UTF-8 and the backslash are escaped (\n, \t, \xHH, \\), and the
 * text is cut after @p max bytes of input with "...(N bytes)" saying how long it was.
 */
std::string printable(std::string_view raw, std::size_t max = 60);

/**
 * A message as the CLI prints it: one line (line breaks become "; "), printable
 * (see printable()), at most @p max characters: a longer one keeps its start
 * (where the file, line or key is named) and its end (what is accepted),
 * joined by " ... ".
 */
std::string oneLine(std::string_view msg, std::size_t max = 300);

/**
 * Names the input a piece of code is processing (a file, usually), for errors
 * that are not navimpact::Error (out of memory, an exception from a third-party
 * library): when such an exception leaves the scope, the innermost scope it
 * crossed is remembered and failedInput() returns it, so that the CLI can still
 * say which input it was working on. Scopes nest; per thread.
 */
class InputScope {
 public:
  explicit InputScope(std::string name);
  ~InputScope();
  InputScope(const InputScope&) = delete;
  InputScope& operator=(const InputScope&) = delete;
  /// Innermost input an exception left since the last clearFailedInput(), or "".
  static std::string failedInput();
  static void clearFailedInput();

 private:
  std::string name_;
  int uncaught_;
};

}  // namespace navimpact
