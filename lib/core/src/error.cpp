#include "navimpact/core/error.hpp"

namespace navimpact {

Error fileError(const std::string& file, std::size_t line, const std::string& what) {
  std::string msg = file;
  if (line > 0) msg += ":" + std::to_string(line);
  msg += ": " + what;
  return Error(msg);
}

Error keyError(const std::string& file, const std::string& key, const std::string& what) {
  std::string msg;
  if (!file.empty()) msg = file + ": ";
  msg += "key '" + key + "': " + what;
  return Error(msg);
}

}  // namespace navimpact
