/**
 * @file model_entry.hpp
 * @brief The one way an IMU error model enters the filter: converted to the
 *        filter's IMU rate, with the state layout the filter builds from it and
 *        the notes saying what changed.
 *
 * Every command that runs or describes the filter (study, covariance and its
 * --print-states, diagnose, replay) asks layoutFor() what the filter will do
 * with a model instead of rebuilding a StateLayout itself; ErrorStateEkf builds
 * its layout through it too, so the two never disagree.
 */
#pragma once

#include <string>
#include <vector>

#include "navimpact/filter/ekf.hpp"
#include "navimpact/filter/state_layout.hpp"
#include "navimpact/stochastic/model_file.hpp"

namespace navimpact::filter {

/// A model as the filter takes it.
struct ModelEntry {
  stochastic::ImuModel model;       ///< at the filter's IMU rate (give this one to ErrorStateEkf)
  StateLayout layout;               ///< the layout ErrorStateEkf builds for it with the same EkfConfig
  std::vector<std::string> notes;   ///< the rate conversion (stochastic::atRate's wording), then
                                    ///< the GMs entered as white noise (StateLayout::notes), one line each
};

/**
 * What the filter makes of @p model.
 * @param[in] model        a six-axis model at any rate.
 * @param[in] cfg          the filter's configuration (propagate_every decides
 *                         which GMs enter as white noise: effectiveImuOptions).
 * @param[in] imu_rate_hz  the filter's IMU rate [Hz]; the model is converted
 *                         exactly to it when it differs (and a note says so);
 *                         0 keeps the model's own rate.
 */
ModelEntry layoutFor(const stochastic::ImuModel& model, const EkfConfig& cfg, double imu_rate_hz = 0.0);

}  // namespace navimpact::filter
