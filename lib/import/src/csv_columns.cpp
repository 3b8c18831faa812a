#include "navimpact/import/csv_columns.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string_view>

#include "navimpact/core/error.hpp"
#include "navimpact/core/gz_input.hpp"
#include "navimpact/core/text_io.hpp"

namespace navimpact::import {

namespace {

std::string_view cleanName(std::string_view n) {
  n = trim(n);
  if (n.size() >= 2 && n.front() == '"' && n.back() == '"') n = trim(n.substr(1, n.size() - 2));
  return n;
}

}  // namespace

ColumnTable readColumns(const std::string& path, const std::vector<ColumnRequest>& req, char delimiter) {
  InputScope scope(path);
  // Streamed (lines of at most 1 MiB, plain or gzip): memory is the columns
  // kept, not the file's text (a 10^6-row IMU file is ~70 MB of text).
  LineReader reader(path);

  // --- header ---------------------------------------------------------------
  std::string_view header;
  bool found = false;
  while (reader.next(header)) {
    const auto t = trim(header);
    if (t.empty() || t.front() == '#') continue;
    found = true;
    break;
  }
  if (!found) throw fileError(path, 0, "file is empty (expected a header line naming the columns)");
  const std::size_t headerLine = reader.lineNo();
  const std::string headerText(header);  // the reader's buffer moves on
  header = headerText;
  const auto names = splitView(header, delimiter);
  const std::size_t ncol = names.size();
  std::vector<int> slot(ncol, -1);             // the request that parses column c, -1 = not parsed
  std::vector<std::size_t> colOf(req.size());  // the column of request r
  std::vector<std::string> headerUnit(req.size());
  for (std::size_t r = 0; r < req.size(); ++r) {
    int at = -1;
    for (int pass = 0; pass < 2 && at < 0; ++pass)
      for (std::size_t c = 0; c < ncol; ++c) {
        std::string_view n = cleanName(names[c]);
        if (pass == 1) {
          const auto lb = n.find('[');
          if (lb == std::string_view::npos) continue;
          n = trim(n.substr(0, lb));
        }
        if (n == req[r].name) {
          if (at >= 0)
            throw fileError(path, headerLine, "column '" + printable(req[r].name) + "' (key " + req[r].key +
                                                  ") appears more than once in the header");
          at = static_cast<int>(c);
        }
      }
    if (at < 0)
      throw fileError(path, headerLine, "no column '" + printable(req[r].name) + "' (key " + req[r].key +
                                            ") in the header '" + printable(trim(header), 100) + "'");
    // several requests may name one column, also as "x" and "x[unit]": the
    // first parses it (a second name of it used to be mapped to column 0)
    colOf[r] = static_cast<std::size_t>(at);
    if (slot[at] < 0) slot[at] = static_cast<int>(r);
    const std::string_view full = cleanName(names[at]);
    if (const auto lb = full.find('['); lb != std::string_view::npos) {
      const auto rb = full.find(']', lb);
      headerUnit[r] = std::string(trim(full.substr(lb + 1, rb == std::string_view::npos ? std::string_view::npos : rb - lb - 1)));
    }
  }

  // --- rows -----------------------------------------------------------------
  ColumnTable t;
  std::vector<std::vector<double>> byCol(ncol);
  {  // reserve from the stated decompressed size and the header's line length
    const std::size_t approx =
        static_cast<std::size_t>(std::min<std::uint64_t>(reader.input().statedSize() / (header.size() + 1) + 16,
                                                         std::uint64_t(1) << 20));
    for (std::size_t c = 0; c < ncol; ++c)
      if (slot[c] >= 0) byCol[c].reserve(approx);
    t.line.reserve(approx);
  }
  std::string_view line;
  while (reader.next(line)) {
    if (trim(line).empty()) continue;
    std::size_t c = 0, start = 0;
    for (;; ++c) {
      std::size_t cut = line.find(delimiter, start);
      const bool last = cut == std::string_view::npos;
      if (last) cut = line.size();
      if (c >= ncol)
        throw fileError(path, reader.lineNo(), "more fields than the " + std::to_string(ncol) + " header columns");
      if (slot[c] >= 0) {
        const ColumnRequest& rq = req[slot[c]];
        const std::string_view field = line.substr(start, cut - start);
        double v;
        if (!parseDouble(field, v)) {
          if (rq.allow_empty && trim(field).empty()) {
            v = NAN;
          } else {
            throw fileError(path, reader.lineNo(), "column '" + printable(rq.name) + "' (key " + rq.key + "): '" +
                                              printable(field) + "' is not a number");
          }
        } else if (!std::isfinite(v)) {
          throw fileError(path, reader.lineNo(), "column '" + printable(rq.name) + "' (key " + rq.key + "): value is " +
                                            printable(trim(field)) + " (finite numbers only)");
        }
        byCol[c].push_back(v);
      }
      if (last) break;
      start = cut + 1;
    }
    if (c + 1 != ncol)
      throw fileError(path, reader.lineNo(), "missing fields: " + std::to_string(c + 1) + " of the " + std::to_string(ncol) +
                                        " header columns");
    t.line.push_back(static_cast<std::uint32_t>(reader.lineNo()));
  }
  if (t.line.empty()) throw fileError(path, headerLine, "no data rows after the header");
  t.header_line = headerLine;
  t.header_unit = std::move(headerUnit);
  t.column = colOf;
  t.columns.resize(req.size());
  for (std::size_t r = 0; r < req.size(); ++r) {
    std::size_t first = r;
    for (std::size_t q = 0; q < r; ++q)
      if (colOf[q] == colOf[r]) { first = q; break; }
    t.columns[r] = first < r ? t.columns[first] : std::move(byCol[colOf[r]]);
  }
  return t;
}

}  // namespace navimpact::import
