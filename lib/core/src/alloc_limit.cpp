#include "navimpact/core/alloc_limit.hpp"

#include <cstdlib>
#include <new>

namespace navimpact {
namespace {
thread_local std::size_t t_limit = 0;
thread_local std::size_t t_refused = 0;

[[noreturn]] void refuse(std::size_t n) {
  t_refused = n;
  throw std::bad_alloc();
}

void* allocate(std::size_t n) {
  if (t_limit != 0 && n > t_limit) refuse(n);
  for (;;) {
    if (void* p = std::malloc(n ? n : 1)) return p;
    std::new_handler h = std::get_new_handler();
    if (!h) throw std::bad_alloc();
    h();
  }
}

void* allocateAligned(std::size_t n, std::size_t align) {
  if (t_limit != 0 && n > t_limit) refuse(n);
  if (align < sizeof(void*)) align = sizeof(void*);
  for (;;) {
    void* p = nullptr;
    if (posix_memalign(&p, align, n ? n : 1) == 0) return p;
    std::new_handler h = std::get_new_handler();
    if (!h) throw std::bad_alloc();
    h();
  }
}
}  // namespace

AllocationLimit::AllocationLimit(std::size_t max_bytes) : previous_(t_limit) { t_limit = max_bytes; }
AllocationLimit::~AllocationLimit() { t_limit = previous_; }

std::size_t AllocationLimit::takeRefused() {
  const std::size_t n = t_refused;
  t_refused = 0;
  return n;
}

std::size_t AllocationLimit::current() { return t_limit; }

}  // namespace navimpact

// Replacements of the global allocation functions (the nothrow forms of
// libstdc++ call these; the default operator delete frees with free(), which
// matches malloc and posix_memalign).
void* operator new(std::size_t n) { return navimpact::allocate(n); }
void* operator new[](std::size_t n) { return navimpact::allocate(n); }
void* operator new(std::size_t n, std::align_val_t a) {
  return navimpact::allocateAligned(n, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t n, std::align_val_t a) {
  return navimpact::allocateAligned(n, static_cast<std::size_t>(a));
}
