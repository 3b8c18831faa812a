// timing.json, the one writer (see timing.hpp).
#include "navimpact/report/timing.hpp"

#include <nlohmann/json.hpp>

#include "navimpact/core/error.hpp"

namespace navimpact::report {

void writeTiming(OutputSet& out, const nlohmann::json& figures) {
  if (!figures.is_object()) throw Error("timing.json: the figures must be a JSON object");
  out.writeText("timing.json", figures.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

}  // namespace navimpact::report
