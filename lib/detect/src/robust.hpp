// Robust location/scale helpers shared by the detectors (not installed).
#pragma once

#include <cstddef>
#include <vector>

namespace navimpact::detect {

/// Median of @p v (taken by value, partially sorted).
double median(std::vector<double> v);

/// 1.4826 * median |v - median(v)| (Gaussian-consistent); *med_out = median.
double madScale(const std::vector<double>& v, double* med_out = nullptr);

/// Upper normal quantile z with P(|N(0,1)| > z) = p.
double twoSidedNormalQuantile(double p);

}  // namespace navimpact::detect
