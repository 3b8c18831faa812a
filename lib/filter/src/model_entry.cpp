// The one model-entry path of the filter (see model_entry.hpp).
#include "navimpact/filter/model_entry.hpp"

namespace navimpact::filter {

ModelEntry layoutFor(const stochastic::ImuModel& model, const EkfConfig& cfg, double imu_rate_hz) {
  ModelEntry e;
  e.model = imu_rate_hz > 0.0 ? stochastic::atRate(model, imu_rate_hz, &e.notes) : model;
  e.layout = StateLayout::build(e.model, effectiveImuOptions(e.model, cfg));
  e.notes.insert(e.notes.end(), e.layout.notes().begin(), e.layout.notes().end());
  return e;
}

}  // namespace navimpact::filter
