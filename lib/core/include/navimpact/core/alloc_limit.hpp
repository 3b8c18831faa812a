/**
 * @file alloc_limit.hpp
 * @brief A per-thread cap on single allocations while decoding untrusted input.
 *
 * Third-party decoders (MRPT's deserialisation) read a length field and
 * allocate that much before they read the data: a 400 KB file with one string
 * length of 0xffffffff would zero-fill 4 GiB. While an AllocationLimit is alive
 * on a thread, any single `operator new` of that thread asking for more than
 * the limit throws std::bad_alloc instead (and the request is remembered), so
 * the reader can report the malformed entry. Readers set the limit from the
 * size of the file (a length field cannot ask for more than the file holds).
 * Implemented by replacing the global operator new (standard C++; the
 * replacement forwards to malloc like the default one).
 */
#pragma once

#include <cstddef>

namespace navimpact {

class AllocationLimit {
 public:
  explicit AllocationLimit(std::size_t max_bytes);
  ~AllocationLimit();
  AllocationLimit(const AllocationLimit&) = delete;
  AllocationLimit& operator=(const AllocationLimit&) = delete;
  /// Size of the last request refused on this thread (0 if none), and reset it.
  static std::size_t takeRefused();
  /// The limit in force on this thread (0 = none).
  static std::size_t current();

 private:
  std::size_t previous_;
};

}  // namespace navimpact
