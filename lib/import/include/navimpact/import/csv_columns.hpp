/**
 * @file csv_columns.hpp
 * @brief Read named numeric columns of a CSV file (plain or gzip) with a header.
 *
 * The first line that is not empty and does not start with '#' is the header;
 * columns are found by name (surrounding spaces and double quotes ignored; a
 * header name "gyro_x[deg/s]" also answers to "gyro_x"). Columns that are not
 * asked for are not parsed. Every error names the file, the line and the
 * manifest key that asked for the column.
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace navimpact::import {

/// One column asked for.
struct ColumnRequest {
  std::string name;          ///< header name
  std::string key;           ///< manifest key that names it (for messages), e.g. "imu.gyro.columns[0]"
  bool allow_empty = false;  ///< an empty field is read as NaN (absent); otherwise it is an error
};

/// The columns read, in the order asked, and the file line of every row.
struct ColumnTable {
  std::vector<std::vector<double>> columns;  ///< columns[i][row]
  std::vector<std::uint32_t> line;           ///< 1-based file line of each row
  std::size_t header_line = 0;               ///< 1-based file line of the header
  /// The unit the header writes in brackets for each request's column
  /// ("deg/s" for "gyro_x[deg/s]"), "" when none: the caller checks it
  /// against the unit it was told.
  std::vector<std::string> header_unit;
  std::vector<std::size_t> column;  ///< 0-based header column of each request (two names may be one column)
  std::size_t rows() const { return line.size(); }
};

/**
 * Read the columns @p req of @p path.
 * @param[in] delimiter  field separator (',', ';' or '\t').
 * @throws navimpact::Error "FILE:LINE: ..." for an empty file, a column not in
 *         the header (listing the header), a row with too few or too many
 *         fields, a field that is not a number, NaN or infinite, an empty
 *         field where it is not allowed.
 */
ColumnTable readColumns(const std::string& path, const std::vector<ColumnRequest>& req, char delimiter = ',');

}  // namespace navimpact::import
