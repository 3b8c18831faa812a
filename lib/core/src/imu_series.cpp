#include "navimpact/core/imu_series.hpp"

#include "navimpact/core/error.hpp"

namespace navimpact {

int channelIndex(const std::string& name) {
  for (std::size_t i = 0; i < kChannelNames.size(); ++i)
    if (name == kChannelNames[i]) return static_cast<int>(i);
  return -1;
}

units::Quantity channelQuantity(const std::string& name) {
  return name.rfind("gyro", 0) == 0 ? units::Quantity::AngularRate
                                    : units::Quantity::SpecificForce;
}

const ImuChannel& ImuSeries::channel(const std::string& name) const {
  for (const auto& c : channels)
    if (c.name == name) return c;
  throw Error(source + ": no channel '" + name + "'");
}

bool ImuSeries::has(const std::string& name) const {
  for (const auto& c : channels)
    if (c.name == name) return true;
  return false;
}

}  // namespace navimpact
