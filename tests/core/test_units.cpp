#include <gtest/gtest.h>

#include "navimpact/core/error.hpp"
#include "navimpact/core/units.hpp"

using namespace navimpact;
using units::Quantity;

TEST(Units, ConvertsHumanUnitsToSi) {
  EXPECT_DOUBLE_EQ(units::toSiFactor(Quantity::AngularRate, "deg/s"), units::kPi / 180.0);
  EXPECT_DOUBLE_EQ(units::toSiFactor(Quantity::AngularRate, "deg/h"), units::kPi / 180.0 / 3600.0);
  EXPECT_DOUBLE_EQ(units::toSiFactor(Quantity::SpecificForce, "g"), 9.80665);
  EXPECT_DOUBLE_EQ(units::toSiFactor(Quantity::SpecificForce, "mg"), 9.80665e-3);
  EXPECT_DOUBLE_EQ(units::toSiFactor(Quantity::SpecificForce, "m/s2"), 1.0);
}

TEST(Units, UnknownUnitNamesTheUnitAndTheChoices) {
  try {
    units::toSiFactor(Quantity::AngularRate, "rpm");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'rpm'"), std::string::npos) << m;
    EXPECT_NE(m.find("deg/s"), std::string::npos) << m;
  }
  // A force unit is not a rate unit.
  EXPECT_THROW(units::toSiFactor(Quantity::AngularRate, "g"), Error);
}
