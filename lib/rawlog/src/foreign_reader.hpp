// Rawlogs navimpact did not write (internal to lib/rawlog; see writer.hpp, readRawlog).
#pragma once

#include "entry_reader.hpp"
#include "navimpact/rawlog/writer.hpp"

namespace navimpact::rawlog::detail {

/// Horizontal velocity from NMEA RMC/VTG: assumed 1-sigma per axis [m/s] (the
/// sentences carry none) and the vertical's, which they do not give [m/s].
constexpr double kRmcSigmaH = 0.1;
constexpr double kRmcSigmaV = 100.0;

/// Read every entry of @p reader as MRPT's drivers record them (see readRawlog).
Recording readForeignRawlog(EntryReader& reader, const RawlogReadOptions& opt);

}  // namespace navimpact::rawlog::detail
