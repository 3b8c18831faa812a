#include "navimpact/core/csv_reader.hpp"
#include "navimpact/core/recording.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>

#include "navimpact/core/error.hpp"
#include "navimpact/core/format.hpp"
#include "navimpact/core/limits.hpp"
#include "navimpact/core/gz_input.hpp"
#include "navimpact/core/text_io.hpp"
#include "navimpact/core/units.hpp"

namespace navimpact {

void parseAxesSpec(const std::string& spec, int src[3], double sign[3]) {
  const auto parts = splitView(spec, ',');
  bool used[3] = {false, false, false};
  auto bad = [&](const std::string& why) {
    return Error("axes spec '" + printable(spec) + "': " + why +
                 " (expected a signed permutation of x,y,z such as \"x,-y,-z\")");
  };
  if (parts.size() != 3) throw bad("needs three comma-separated axes");
  for (int i = 0; i < 3; ++i) {
    std::string_view p = trim(parts[i]);
    double s = 1.0;
    if (!p.empty() && (p.front() == '-' || p.front() == '+')) {
      s = p.front() == '-' ? -1.0 : 1.0;
      p.remove_prefix(1);
    }
    if (p.size() != 1 || p[0] < 'x' || p[0] > 'z') throw bad("unknown axis '" + printable(parts[i]) + "'");
    const int a = p[0] - 'x';
    if (used[a]) throw bad("axis '" + std::string(p) + "' used twice");
    used[a] = true;
    src[i] = a;
    sign[i] = s;
  }
}

namespace {

struct Column {
  int channel = -1;  // canonical index, -1 = ignored, -2 = time
  double factor = 1.0;
};

/// The time columns read without --time-column.
bool isDefaultTimeName(const std::string& n) { return n == "t" || n == "t_s" || n == "time_s" || n == "time"; }

/// @p n in lower case without separators ("Gyro_X" -> "gyrox").
std::string foldName(const std::string& n) {
  std::string f;
  for (const char ch : n)
    if (std::isalnum(static_cast<unsigned char>(ch))) f += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return f;
}

/// A column name of time stamps: t, time..., t_..., ...stamp..., ..._time, in any case.
bool looksLikeTime(const std::string& n) {
  std::string l;
  for (const char ch : n) l += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  auto ends = [&l](const char* suf) {
    const std::size_t k = std::strlen(suf);
    return l.size() >= k && l.compare(l.size() - k, k, suf) == 0;
  };
  return l == "t" || l.rfind("time", 0) == 0 || l.rfind("t_", 0) == 0 || l.find("stamp") != std::string::npos ||
         ends("_time") || ends("_t");
}

/// A time stamp in long double (64-bit mantissa: Unix nanoseconds exact);
/// false for no number or a non-finite one.
bool parseStamp(std::string_view s, long double& out) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto res = std::from_chars(s.data(), s.data() + s.size(), out);
  return res.ec == std::errc() && res.ptr == s.data() + s.size() && std::isfinite(out);
}

}  // namespace

ImuSeries readImuCsv(const std::string& path, const CsvImuOptions& opt) {
  InputScope scope(path);
  // Streamed line by line (bounded memory: one buffer plus the samples), each
  // line at most LineReader::kDefaultMaxLine bytes.
  LineReader lines(path);
  std::string_view first;
  bool any = false;
  while (lines.next(first))
    if (!trim(first).empty()) {
      any = true;
      break;
    }
  if (!any) throw fileError(path, 0, "file is empty");
  if (lines.lineNo() != 1) throw fileError(path, lines.lineNo(), "the header must be the first line");

  // --- header --------------------------------------------------------------
  const std::string headerText(first);
  std::string_view header(headerText);
  std::size_t lineNo = 1;
  const auto names = splitView(header, ',');
  std::vector<Column> cols(names.size());
  int timeCol = -1;
  std::string timeName, timeLike;  // the time column read; a column that looks like one
  double timeFactor = 1.0;  // seconds per unit of the time column
  std::string timeUnit = "s";
  int present[6] = {-1, -1, -1, -1, -1, -1};
  for (std::size_t c = 0; c < names.size(); ++c) {
    std::string_view n = trim(names[c]);
    std::string unit;
    const auto lb = n.find('[');
    if (lb != std::string_view::npos) {
      const auto rb = n.find(']', lb);
      if (rb == std::string_view::npos)
        throw fileError(path, 1, "column " + std::to_string(c + 1) + " '" + printable(n) +
                                     "': unit bracket not closed");
      unit = std::string(trim(n.substr(lb + 1, rb - lb - 1)));
      n = trim(n.substr(0, lb));
    }
    const std::string name(n);
    if (opt.time_column.empty() ? isDefaultTimeName(name) : name == opt.time_column) {
      if (timeCol >= 0)
        throw fileError(path, 1, "column " + std::to_string(c + 1) + " '" + printable(name) +
                                     "': a second time column (the first is column " + std::to_string(timeCol + 1) +
                                     ")");
      timeCol = static_cast<int>(c);
      timeName = name;
      cols[c].channel = -2;
      // the stamps' unit: the header's, or time_unit; both given, they must agree
      if (!unit.empty() && !opt.time_unit.empty() && unit != opt.time_unit)
        throw fileError(path, 1, "time column '" + printable(name) + "' is in " + printable(unit) +
                                     " by its header, but --time-unit says " + printable(opt.time_unit) +
                                     ": drop the flag or correct the header");
      timeUnit = unit.empty() ? (opt.time_unit.empty() ? std::string("s") : opt.time_unit) : unit;
      try {
        timeFactor = units::secondsPer(timeUnit);
      } catch (const Error& e) {
        throw fileError(path, 1, "time column '" + printable(name) + "': " + e.what());
      }
      continue;
    }
    const int idx = channelIndex(name);
    if (idx < 0) {
      // a channel's name written otherwise (Gyro_X, gyrox) would leave the
      // channel out without a word, and a fit would model it as "none"
      const std::string folded = foldName(name);
      for (const char* ch : kChannelNames)
        if (folded == foldName(ch))
          throw fileError(path, 1, "column " + std::to_string(c + 1) + " '" + printable(name) +
                                       "' is not a channel name: write it " + ch +
                                       " (names are exact: gyro_x gyro_y gyro_z acc_x acc_y acc_z)");
      if (timeLike.empty() && looksLikeTime(name)) timeLike = name;
      continue;
    }
    if (present[idx] >= 0)
      throw fileError(path, 1, "column '" + name + "' appears twice");
    present[idx] = static_cast<int>(c);
    const auto q = channelQuantity(name);
    const std::string& told = q == units::Quantity::AngularRate ? opt.gyro_unit : opt.acc_unit;
    if (!unit.empty() && !told.empty()) {
      // both the header and the caller name the unit: they must agree (the
      // header used to win silently while the caller recorded its own unit)
      double fh = 0, ft = 0;
      try {
        fh = units::toSiFactor(q, unit);
        ft = units::toSiFactor(q, told);
      } catch (const Error& e) {
        throw fileError(path, 1, "column '" + printable(name) + "': " + e.what());
      }
      if (fh != ft)
        throw fileError(path, 1,
                        "column '" + printable(name) + "' is in " + printable(unit) + " by its header, but --" +
                            (q == units::Quantity::AngularRate ? "gyro" : "acc") + "-unit says " + printable(told) +
                            ": drop the flag or correct the header");
    }
    if (unit.empty()) unit = told;
    if (unit.empty())
      throw fileError(path, 1,
                      "unit of column '" + name + "' unknown: pass --" +
                          (q == units::Quantity::AngularRate ? "gyro" : "acc") +
                          "-unit or write it in the header as " + name + "[unit]");
    try {
      cols[c].factor = units::toSiFactor(q, unit);
    } catch (const Error& e) {
      throw fileError(path, 1, "column '" + printable(name) + "': " + e.what());
    }
    cols[c].channel = idx;
  }
  // stamps in a column that is not read as time: the rate would come from
  // --rate unchecked (the katwijk IMU's t_s at 125 Hz read at --rate 100)
  if (timeCol < 0 && opt.time_column.empty() && !timeLike.empty())
    throw fileError(path, 1, "column '" + printable(timeLike) +
                                 "' looks like time stamps but is not read as time: pass --time-column " +
                                 printable(timeLike) + " (the default time columns are t, t_s, time_s, time)");
  if (!opt.time_column.empty() && timeCol < 0)
    throw fileError(path, 1,
                    "no time column '" + printable(opt.time_column) + "' (--time-column) in header '" +
                        printable(trim(header), 120) + "'");
  if (std::all_of(std::begin(present), std::end(present), [](int p) { return p < 0; }))
    throw fileError(path, 1,
                    "no IMU column in header '" + printable(trim(header), 120) +
                        "' (expected some of gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z and optional t)");

  // --- rows ----------------------------------------------------------------
  std::vector<std::vector<double>> data(6);
  // Capacity from the size the file states and the header's length (a guess; vectors still grow).
  const std::size_t approxRows = static_cast<std::size_t>(std::min<std::uint64_t>(
      lines.input().statedSize() / std::max<std::size_t>(header.size(), 8) + 16, std::uint64_t(1) << 26));
  for (int i = 0; i < 6; ++i)
    if (present[i] >= 0) data[i].reserve(approxRows);
  std::vector<double> times;  // [s] from the first stamp
  long double firstStamp = 0.0L, prevStamp = 0.0L;  // in the column's unit
  if (timeCol >= 0) times.reserve(approxRows);

  const std::size_t ncol = cols.size();
  std::string_view line;
  while (lines.next(line)) {
    lineNo = lines.lineNo();
    if (trim(line).empty()) continue;
    std::size_t c = 0, start = 0;
    for (;; ++c) {
      std::size_t comma = line.find(',', start);
      const bool last = comma == std::string_view::npos;
      if (last) comma = line.size();
      if (c >= ncol)
        throw fileError(path, lineNo, "more fields than the " + std::to_string(ncol) + " header columns");
      if (cols[c].channel == -2) {
        // a stamp, read in long double and kept relative to the first: Unix
        // nanoseconds (~1.7e18) lose 256 ns in a double, Unix seconds 0.24 us
        long double v;
        const std::string_view field = line.substr(start, comma - start);
        if (!parseStamp(field, v))
          throw fileError(path, lineNo, "column " + std::to_string(c + 1) + " ('" +
                                            printable(trim(names[c])) + "'): '" + printable(field) +
                                            "' is not a finite number");
        if (times.empty()) firstStamp = v;
        else if (!(v > prevStamp))
          throw fileError(path, lineNo, "time " + formatNumber(static_cast<double>(v), 10) + " " + timeUnit +
                                            " is not after the previous " + formatNumber(static_cast<double>(prevStamp), 10) +
                                            " " + timeUnit);
        prevStamp = v;
        times.push_back(static_cast<double>((v - firstStamp) * timeFactor));
      } else if (cols[c].channel != -1) {
        double v;
        const std::string_view field = line.substr(start, comma - start);
        if (!parseDouble(field, v))
          throw fileError(path, lineNo, "column " + std::to_string(c + 1) + " ('" +
                                            printable(trim(names[c])) + "'): '" + printable(field) +
                                            "' is not a number");
        if (!std::isfinite(v))
          throw fileError(path, lineNo, "column " + std::to_string(c + 1) + " ('" +
                                            printable(trim(names[c])) + "'): value is " +
                                            printable(trim(field)));
        {
          const double si = v * cols[c].factor;
          const double lim = maxAbsSample(channelQuantity(kChannelNames[cols[c].channel]));
          if (!(std::abs(si) <= lim))
            throw fileError(path, lineNo, "column " + std::to_string(c + 1) + " ('" + printable(trim(names[c])) +
                                              "'): " + printable(trim(field)) + " is beyond any IMU (|value| <= " +
                                              (lim == kMaxAbsAngularRate ? "1000 rad/s" : "1e5 m/s^2") +
                                              " in SI); check the data and the unit");
          data[cols[c].channel].push_back(si);
        }
      }
      if (last) break;
      start = comma + 1;
    }
    if (c + 1 != ncol)
      throw fileError(path, lineNo, "missing field: " + std::to_string(c + 1) + " of " +
                                        std::to_string(ncol) + " columns");
  }
  std::size_t n = 0;
  for (int i = 0; i < 6; ++i)
    if (present[i] >= 0) n = data[i].size();
  if (n == 0) throw fileError(path, 0, "header but no data rows");

  // --- time base -------------------------------------------------------------
  ImuSeries out;
  out.source = path;
  if (timeCol >= 0) {
    if (n < 2) throw fileError(path, 0, "need at least two rows to derive the rate from 't'");
    // stamp k as the file has it (its unit), for messages
    auto stampText = [&](std::size_t k) {
      return formatNumber(static_cast<double>(firstStamp + times[k] / timeFactor), 10) + " " + timeUnit;
    };
    std::vector<double> dts(n - 1);
    for (std::size_t k = 1; k < n; ++k) {
      dts[k - 1] = times[k] - times[k - 1];
      if (!(dts[k - 1] > 0.0))
        throw fileError(path, k + 2, "time " + stampText(k) + " is not after the previous " + stampText(k - 1) +
                                         " (step " + formatNumber(dts[k - 1]) + " s)");
    }
    // The nominal step (the median; the mean where quantised or alternating
    // stamps move the median: 400 Hz stamped in ms, nominalStep). A step is
    // regular when within max_dt_deviation of it, or when its stamp lies
    // within half a step of the regular grid t0 + k T and its step too (stamps quantised
    // or jittered around a regular clock); a lost sample is neither.
    const double med = nominalStep(dts);
    for (std::size_t k = 0; k < dts.size(); ++k) {
      const double off = times[k + 1] - times[0] - static_cast<double>(k + 1) * med;
      if (std::abs(dts[k] - med) > opt.max_dt_deviation * med &&
          !(std::abs(off) < 0.5 * med && std::abs(dts[k] - med) < 0.5 * med))
        throw fileError(path, k + 3, "time step " + formatNumber(dts[k]) + " s differs from the nominal " +
                                         formatNumber(med) + " s (gap or jitter); resample or split the recording");
    }
    // stamps on a file's time axis (Unix seconds at most): a unit 1000x off
    // in Unix time (ms read as s) is 1.7e12 "s", a 1 Hz record in range
    for (const long double v : {firstStamp, prevStamp})
      if (!(std::fabs(static_cast<double>(v * timeFactor)) <= limits::kFileTimeS.hi))
        throw fileError(path, 0, "time column '" + printable(timeName) + "' holds " + formatNumber(static_cast<double>(v), 10) +
                                     " " + timeUnit +
                                     (timeUnit == "s" ? "" : " = " + formatNumber(static_cast<double>(v * timeFactor), 10) + " s") +
                                     ", outside " + limits::describe(limits::kFileTimeS) + " (is the time unit right?)");
    // from the stamps in their unit (1, 1e3, 1e6, 1e9 per second: exact), one rounding
    const long double perSecond = std::round(1.0L / timeFactor);
    const double rate = static_cast<double>((n - 1) * perSecond / (prevStamp - firstStamp));
    // the documented range of IMU rates (a time column in the wrong unit: a step of 1e300 s or 1 ns)
    if (!(rate >= limits::kImuRateHz.lo && rate <= limits::kImuRateHz.hi))
      throw fileError(path, 0, "the time column gives a rate of " + formatNumber(rate) + " Hz, outside " +
                                   limits::describe(limits::kImuRateHz) + " (is the time unit right?)");
    if (opt.rate_hz && std::abs(*opt.rate_hz - rate) > 1e-3 * rate)
      throw fileError(path, 0, "--rate " + formatNumber(*opt.rate_hz) +
                                   " Hz disagrees with the time column (" + formatNumber(rate) + " Hz)");
    out.rate_hz = opt.rate_hz ? *opt.rate_hz : rate;
    out.t0_s = static_cast<double>(firstStamp * timeFactor);
    out.time_column = timeName;
    out.time_unit = timeUnit;
  } else {
    if (!opt.time_unit.empty())
      throw fileError(path, 1, "time unit '" + printable(opt.time_unit) +
                                   "' given, but the header has no time column (t, t_s, time_s, time or --time-column NAME)");
    if (!opt.rate_hz)
      throw fileError(path, 1, "no time column (t, t_s, time_s, time or --time-column NAME): the sampling rate must be given (--rate HZ)");
    if (!(*opt.rate_hz > 0.0) || !std::isfinite(*opt.rate_hz))
      throw Error("rate must be a positive number of Hz");
    out.rate_hz = *opt.rate_hz;
  }

  // --- axes remap -------------------------------------------------------------
  if (!opt.axes.empty()) {
    int src[3];
    double sign[3];
    parseAxesSpec(opt.axes, src, sign);
    for (int s = 0; s < 2; ++s) {  // gyro block then acc block
      const int b = 3 * s;
      bool all = present[b] >= 0 && present[b + 1] >= 0 && present[b + 2] >= 0;
      bool none = present[b] < 0 && present[b + 1] < 0 && present[b + 2] < 0;
      if (!all && !none)
        throw fileError(path, 1, std::string("--axes needs all three ") + (s ? "acc" : "gyro") + " columns");
      if (none) continue;
      std::vector<double> tmp[3] = {std::move(data[b]), std::move(data[b + 1]), std::move(data[b + 2])};
      for (int i = 0; i < 3; ++i) {
        data[b + i] = tmp[src[i]];
        if (sign[i] < 0)
          for (auto& v : data[b + i]) v = -v;
      }
    }
  }
  for (int i = 0; i < 6; ++i) {
    if (present[i] < 0) continue;
    ImuChannel ch;
    ch.name = kChannelNames[i];
    ch.quantity = channelQuantity(ch.name);
    ch.x = std::move(data[i]);
    out.channels.push_back(std::move(ch));
  }
  return out;
}

}  // namespace navimpact
