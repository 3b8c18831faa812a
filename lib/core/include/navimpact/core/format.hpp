/**
 * @file format.hpp
 * @brief The one number formatter of navimpact: every number written into a
 *        message, a report, a CSV/YAML file or the console goes through it
 *        (JSON numbers aside: nlohmann::json writes those).
 *
 * Modes (each the C printf conversion named, "C" locale):
 *  - formatNumber(x, n): %.ng, n significant digits, shortest of fixed and
 *    exponent form (what an iostream writes at precision n): 0.1, 1e-05, 200;
 *  - formatExact(x): %.ng with the smallest n in 15..17 that reads back to
 *    x exactly (numbers written to be read again: model files);
 *  - formatFixed(x, d): %.df, d decimals (tables for people);
 *  - formatReadable(x, n): for people: exponent form with n - 1 decimals
 *    when 0 < |x| < 1e-3 or |x| >= 1e5, else %.ng.
 * Not finite: formatNumber and formatExact write "inf", "-inf", "nan" (what
 * a CSV or YAML reader reads back); formatFixed and formatReadable, whose
 * text is for people, write "n/a".
 */
#pragma once

#include <string>

namespace navimpact {

/// %.{significant}g (significant >= 1; 0 is taken as 1 like printf).
std::string formatNumber(double x, int significant = 6);

/// %.{n}g with the smallest n in 15..17 whose text parses back to exactly @p x.
std::string formatExact(double x);

/// %.{decimals}f (decimals >= 0); "n/a" if not finite.
std::string formatFixed(double x, int decimals);

/// "n/a" if not finite; %.{significant-1}e if 0 < |x| < 1e-3 or |x| >= 1e5; else %.{significant}g.
std::string formatReadable(double x, int significant = 3);

}  // namespace navimpact
