#include "navimpact/core/error.hpp"

#include <cstdio>
#include <exception>

namespace navimpact {

Error fileError(const std::string& file, std::size_t line, const std::string& what) {
  std::string msg = file;
  if (line > 0) msg += ":" + std::to_string(line);
  msg += ": " + what;
  return Error(msg);
}

std::string keyPlace(const std::string& file, const std::string& key) {
  return (file.empty() ? std::string() : file + ": ") + "key '" + printable(key, 80) + "'";
}

Error keyError(const std::string& file, const std::string& key, const std::string& what) {
  return Error(keyPlace(file, key) + ": " + what);
}

namespace {

/// Length of the valid UTF-8 sequence starting at s[i] (1..4), or 0 if invalid.
std::size_t utf8Length(std::string_view s, std::size_t i) {
  const auto c = static_cast<unsigned char>(s[i]);
  std::size_t n = 0;
  unsigned min = 0;
  if (c >= 0xC2 && c <= 0xDF) n = 2, min = 0x80;
  else if (c >= 0xE0 && c <= 0xEF) n = 3, min = 0x800;
  else if (c >= 0xF0 && c <= 0xF4) n = 4, min = 0x10000;
  else return 0;
  if (i + n > s.size()) return 0;
  unsigned cp = c & (0x3F >> (n - 1));
  for (std::size_t k = 1; k < n; ++k) {
    const auto d = static_cast<unsigned char>(s[i + k]);
    if ((d & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (d & 0x3F);
  }
  if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return n;
}

/// Appends the escaped form of s[i..] up to @p budget input bytes; returns bytes consumed.
std::size_t appendEscaped(std::string& out, std::string_view s, std::size_t i, std::size_t budget,
                          bool raw = true) {
  const std::size_t start = i;
  while (i < s.size() && i - start < budget) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c == '\\' && raw) {
      out += "\\\\";
      ++i;
    } else if (c == '\t' && !raw) {
      out += ' ';
      ++i;
    } else if (c == '\n') {
      out += "\\n";
      ++i;
    } else if (c == '\t') {
      out += "\\t";
      ++i;
    } else if (c == '\r') {
      out += "\\r";
      ++i;
    } else if (c >= 0x20 && c < 0x7F) {
      out += static_cast<char>(c);
      ++i;
    } else if (const std::size_t n = c >= 0x80 ? utf8Length(s, i) : 0; n > 0) {
      out.append(s.substr(i, n));
      i += n;
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", c);
      out += buf;
      ++i;
    }
  }
  return i - start;
}

thread_local std::string g_failedInput;

}  // namespace

std::string printable(std::string_view raw, std::size_t max) {
  std::string out;
  const std::size_t used = appendEscaped(out, raw, 0, max);
  if (used < raw.size()) out += "...(" + std::to_string(raw.size()) + " bytes)";
  return out;
}

namespace {

/// @p msg flattened: line breaks (and the white space around them) become
/// "; ", raw bytes are escaped; at most @p cap characters of @p msg are read.
std::string flatten(std::string_view msg, std::size_t cap) {
  std::string flat;
  std::size_t i = 0;
  while (i < msg.size() && i < cap) {
    if (msg[i] == '\n' || msg[i] == '\r') {
      while (!flat.empty() && (flat.back() == ' ' || flat.back() == '\t')) flat.pop_back();
      while (i < msg.size() && (msg[i] == '\n' || msg[i] == '\r' || msg[i] == ' ' || msg[i] == '\t')) ++i;
      if (!flat.empty() && i < msg.size()) flat += "; ";
      continue;
    }
    const std::size_t used = appendEscaped(flat, msg, i, 1, false);
    i += used ? used : 1;
  }
  return flat;
}

bool continuationByte(const std::string& s, std::size_t k) {
  return k < s.size() && (static_cast<unsigned char>(s[k]) & 0xC0) == 0x80;
}

/// Runs of more than @p longest non-blank characters (long paths) shortened
/// to their start and end around "...", on character boundaries.
std::string shortenLongWords(const std::string& s, std::size_t longest) {
  std::string out;
  std::size_t i = 0;
  while (i < s.size()) {
    std::size_t j = i;
    while (j < s.size() && s[j] != ' ') ++j;
    if (j - i > longest) {
      std::size_t h = i + longest / 3, t = j - (longest - longest / 3 - 3);
      while (h > i && continuationByte(s, h)) --h;
      while (t < j && continuationByte(s, t)) ++t;
      out.append(s, i, h - i).append("...").append(s, t, j - t);
    } else {
      out.append(s, i, j - i);
    }
    if (j < s.size()) out += ' ';
    i = j + 1;
  }
  return out;
}

}  // namespace

std::string oneLine(std::string_view msg, std::size_t max) {
  // A long message is read at its start (where) and its end (what is wrong,
  // what is accepted); long paths in it are shortened in their middle first.
  const std::size_t cap = 4 * max;
  std::string flat;
  if (msg.size() <= 2 * cap) {
    flat = flatten(msg, msg.size());
  } else {
    std::size_t t = msg.size() - cap;
    while (t < msg.size() && (static_cast<unsigned char>(msg[t]) & 0xC0) == 0x80) ++t;
    flat = flatten(msg.substr(0, cap), cap) + " ... " + flatten(msg.substr(t), cap);
  }
  if (flat.size() <= max) return flat;
  flat = shortenLongWords(flat, 80);
  if (flat.size() <= max) return flat;
  // Keep the start (where) and the end (what is accepted); cut on character boundaries.
  const std::size_t tail = max / 4, head = max - tail - 5;
  std::size_t h = head, t = flat.size() - tail;
  while (h > 0 && continuationByte(flat, h)) --h;
  while (t < flat.size() && continuationByte(flat, t)) ++t;
  return flat.substr(0, h) + " ... " + flat.substr(t);
}

InputScope::InputScope(std::string name) : name_(std::move(name)), uncaught_(std::uncaught_exceptions()) {}

InputScope::~InputScope() {
  // Unwinding because of an exception: the innermost scope it leaves names the input.
  if (std::uncaught_exceptions() > uncaught_ && g_failedInput.empty()) g_failedInput = name_;
}

std::string InputScope::failedInput() { return g_failedInput; }

void InputScope::clearFailedInput() { g_failedInput.clear(); }

}  // namespace navimpact
