/**
 * @file text_io.hpp
 * @brief Whole-file reads (gzip transparent) and small text helpers.
 */
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace navimpact {

/**
 * Read a whole (small) file into memory; gzip-compressed files (any name) are
 * decompressed transparently and strictly (see GzInput). Large inputs are
 * streamed instead (LineReader, GzInput).
 * @throws navimpact::Error naming the file if it cannot be opened, is corrupt,
 *         or holds more than @p max_bytes bytes.
 */
std::string readFileMaybeGz(const std::string& path, std::size_t max_bytes = std::size_t(64) << 20);

/**
 * Why @p path cannot be read as an input file, or "" when it can: the
 * system's reason ("No such file or directory", "Permission denied", "Is a
 * directory", ...), or "not a regular file" for a FIFO, socket or device
 * (reading one could block or never end).
 */
std::string unreadableReason(const std::string& path);

/// Split on a delimiter, no trimming; empty fields are kept.
std::vector<std::string_view> splitView(std::string_view s, char delim);

/// Strip leading and trailing white space.
std::string_view trim(std::string_view s);

/**
 * Parse a whole field as a double (std::from_chars, locale independent); a
 * value below the smallest double (1e-400) is read as it rounds (0).
 * @return false when the field is empty, has trailing garbage or exceeds the
 *         largest double (1e400).
 */
bool parseDouble(std::string_view s, double& out);

}  // namespace navimpact
