/**
 * @file error.hpp
 * @brief The one exception type of navimpact's libraries.
 *
 * Library code never prints and never exits: it throws navimpact::Error with a
 * message that names the place (file, line, column, key) and what was expected.
 * Applications catch it, print one line and return a non-zero exit code.
 */
#pragma once

#include <stdexcept>
#include <string>

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

}  // namespace navimpact
