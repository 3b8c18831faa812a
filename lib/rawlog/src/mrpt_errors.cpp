#include "mrpt_errors.hpp"

#include <new>
#include <sstream>
#include <vector>

#include "navimpact/core/error.hpp"
#include "navimpact/core/text_io.hpp"

namespace navimpact::rawlog::detail {

std::string mrptCause(const std::string& what) {
  std::vector<std::string> messages;
  std::istringstream in(what);
  std::string line;
  while (std::getline(in, line)) {
    const auto t = trim(line);
    if (t.rfind("Message:", 0) == 0) messages.emplace_back(trim(t.substr(8)));
  }
  if (messages.empty()) {  // not an MRPT exception text: its first line
    const auto nl = what.find('\n');
    return printable(trim(std::string_view(what).substr(0, nl)), 160);
  }
  std::string cause = messages.back();
  // "Exception while parsing typed object 'mrpt::obs::CObservationIMU' from ...": the class being read
  std::string reading;
  for (const auto& m : messages) {
    const std::string key = "parsing typed object '";
    const auto p = m.find(key);
    if (p == std::string::npos) continue;
    const auto q = m.find('\'', p + key.size());
    if (q == std::string::npos) continue;
    reading = m.substr(p + key.size(), q - p - key.size());
    if (const auto c = reading.rfind("::"); c != std::string::npos) reading = reading.substr(c + 2);
    break;
  }
  if (!cause.empty()) cause[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(cause[0])));
  if (cause.rfind("exception while parsing typed object", 0) == 0) cause = "malformed data";
  return (reading.empty() ? std::string() : "reading " + printable(reading, 60) + ": ") + printable(cause, 160);
}

std::string mrptCause(const std::exception& e) {
  if (dynamic_cast<const std::bad_alloc*>(&e)) return "a length field asks for more memory than the file can hold";
  return mrptCause(std::string(e.what()));
}

}  // namespace navimpact::rawlog::detail
