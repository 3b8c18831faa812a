// MRPT exceptions as one-line causes (internal to lib/rawlog).
#pragma once

#include <exception>
#include <string>

namespace navimpact::rawlog::detail {

/**
 * The cause of an exception thrown by MRPT, in one short line. MRPT's texts
 * are multi-line ("==== MRPT exception ====", "Message: ...", nested
 * "Original exception:" blocks, source locations and call stacks): this keeps
 * the innermost message (the root cause) and the class that was being read,
 * e.g. "reading CObservationIMU: stored object has class 'mrpt::poses\x8F:CPose3D'
 * which is not registered". Raw bytes are escaped (navimpact::printable).
 */
std::string mrptCause(const std::exception& e);
std::string mrptCause(const std::string& what);

}  // namespace navimpact::rawlog::detail
