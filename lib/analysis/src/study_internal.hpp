// Internal helpers of study.cpp.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <iosfwd>
#include <string>

#include "navimpact/analysis/study.hpp"

namespace navimpact::analysis::detail {

/// Values stored per epoch in a run record: err[9], sigma[9], nees[4].
constexpr int kEpochValues = 22;

/// The StudyHeader fields of a study's or a sweep's meta JSON, written into @p j / read from @p j
/// (json::exception for a missing or mistyped field: the caller names the file).
void headerToJson(const StudyHeader& h, nlohmann::json& j);
void headerFromJson(const nlohmann::json& j, StudyHeader& h);
/// The header as navimpact writes it (a shard read back): runs_total [1, 1e6], unique
/// candidate labels, sets naming only those, margin [0, 10]. @throws Error "WHERE: ...".
void checkHeader(const StudyHeader& h, const std::string& where);

nlohmann::json metaToJson(const StudyMeta& m);
StudyMeta metaFromJson(const nlohmann::json& j, const std::string& where);

/// Run files of shards (runs.bin, sweep_runs.bin): 64-bit counts and doubles
/// as the machine holds them; a short read is "FILE: truncated".
void putU64(std::ostream& o, std::uint64_t v);
void putD(std::ostream& o, const double* v, std::size_t n);
std::uint64_t getU64(std::istream& i, const std::string& file);
void getD(std::istream& i, double* v, std::size_t n, const std::string& file);

/// DIR/FILE of a shard folder, parsed: a JSON object holding the key @p marker.
/// @param writer  the command that writes it ("study --shard"), named when the file is missing.
/// @throws navimpact::Error "DIR/FILE: cannot open (is DIR a folder written by navimpact WRITER?)",
///         "...: not valid JSON (...)" or "...: not a navimpact KIND shard" (KIND: the writer's first word).
nlohmann::json readShardJson(const std::string& dir, const std::string& file, const std::string& marker,
                             const std::string& writer);

/// Largest magnitude of a value in a shard's run file (study and sweep): their
/// squares summed over every run stay finite.
inline constexpr double kMaxRunValue = 1e100;

/// Why a run's record holds a value no run writes, or "": an error beyond
/// kMaxRunValue or not finite, a sigma, drift or time that is not finite and >= 0, a
/// NEES that is neither missing (NaN) nor finite and >= 0. Checked after each
/// run and on each run a merge reads.
std::string implausible(const RunRecord& rec);

/// chi2inv(p, dof) (boost::math).
double chi2Quantile(double p, double dof);

}  // namespace navimpact::analysis::detail
