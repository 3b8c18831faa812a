/**
 * @file timing.hpp
 * @brief timing.json: the wall-clock and CPU figures of a command, written
 *        apart from its result files so that identical inputs give
 *        byte-identical results (the cli_reproducible_* tests compare every
 *        file but this one). Every command that times itself writes it here:
 *        replay, study, diagnose, diagnose-power, sweep (and its shards,
 *        whose filter_steps / filter_wall_s sweep-merge adds up) and
 *        diagnose --run.
 */
#pragma once

#include <nlohmann/json_fwd.hpp>

#include "navimpact/core/output.hpp"

namespace navimpact::report {

/// Stage timing.json in @p out: @p figures, a JSON object (seconds, counts,
/// per-model tables), keys sorted, one space of indent, newline at the end.
void writeTiming(OutputSet& out, const nlohmann::json& figures);

}  // namespace navimpact::report
