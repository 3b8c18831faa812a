/**
 * @file model_text.hpp
 * @brief The one text form of a model, used everywhere (CLI, YAML, JSON, reports):
 *        `WN(sigma=5.521e-3) + GM(sigma=4.811e-4, T=3.22) + DR(omega=9.302e-10)`.
 *
 * Grammar:  model := "none" | term ("+" term)* ;
 *           term  := NAME "(" [ key "=" number ("," key "=" number)* ] ")" ;
 * NAME in WN(sigma) QN(Q) RW(gamma) DR(omega) GM(sigma,T) AR1(phi,sigma2)
 * SIN(amp,freq); white space is free; keys may be given in any order and all
 * are required. A structure spec (`WN+GM+GM+DR`, no parentheses) is parsed by
 * parseStructure().
 */
#pragma once

#include <string>
#include <vector>

#include "navimpact/stochastic/process.hpp"

namespace navimpact::stochastic {

/**
 * Parse a model string. @p rate_hz is needed only for AR1 terms (converted to GM).
 * @throws navimpact::Error "model 'TEXT': at position P: expected X, found Y".
 */
std::vector<Process> parseTerms(const std::string& text, double rate_hz);

/// The model at @p rate_hz whose terms are @p text (parseTerms). @throws navimpact::Error as parseTerms.
Model parseModel(const std::string& text, double rate_hz);

/// Text form with 4 significant digits by default; round-trips exactly with
/// digits=17 (then each number is printed with the shortest of 15/16/17 digits
/// that reads back as the same double, e.g. 4.811e-4 rather than 0.00048109999999999998).
std::string formatTerms(const std::vector<Process>& terms, int digits = 4);

/// Parse a structure like "WN+GM+GM+DR" (also accepts "AR1" for GM, "SIN", "QN", "RW").
std::vector<ProcessKind> parseStructure(const std::string& spec);
std::string formatStructure(const std::vector<ProcessKind>& kinds);
/// The structure of a model's terms, e.g. "WN+GM+DR" ("none" when empty).
std::string formatStructure(const Model& m);

}  // namespace navimpact::stochastic
