#include "navimpact/core/alloc_limit.hpp"

#include <cstddef>
#include <new>

// Deliberately without <cstdlib>: glibc declares its allocation functions
// noexcept, and the aligned_alloc replacement below must be able to throw.
extern "C" void* malloc(std::size_t n);
extern "C" int posix_memalign(void** p, std::size_t align, std::size_t n);

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
    if (void* p = malloc(n ? n : 1)) return p;
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

AllocationLimit::AllocationLimit(std::size_t max_bytes) : previous_(t_limit) {
  // nested limits: the tighter one holds (0 = none)
  t_limit = (previous_ != 0 && (max_bytes == 0 || previous_ < max_bytes)) ? previous_ : max_bytes;
}
AllocationLimit::~AllocationLimit() { t_limit = previous_; }

std::size_t AllocationLimit::takeRefused() {
  const std::size_t n = t_refused;
  t_refused = 0;
  return n;
}

std::size_t AllocationLimit::current() { return t_limit; }

}  // namespace navimpact

// Replacements of every global allocation function (throwing, nothrow,
// aligned) and, below, every deallocation function.
void* operator new(std::size_t n) { return navimpact::allocate(n); }
void* operator new[](std::size_t n) { return navimpact::allocate(n); }
void* operator new(std::size_t n, std::align_val_t a) {
  return navimpact::allocateAligned(n, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t n, std::align_val_t a) {
  return navimpact::allocateAligned(n, static_cast<std::size_t>(a));
}

void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return navimpact::allocate(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return navimpact::allocate(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  try {
    return navimpact::allocateAligned(n, static_cast<std::size_t>(a));
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  try {
    return navimpact::allocateAligned(n, static_cast<std::size_t>(a));
  } catch (...) {
    return nullptr;
  }
}

// The matching deallocation functions free() what the functions above took
// from malloc / posix_memalign (what libstdc++'s defaults do too; replacing
// them with the allocation functions keeps the pair consistent for tools that
// check it, such as AddressSanitizer's alloc-dealloc-mismatch).
extern "C" void free(void* p);
void operator delete(void* p) noexcept { free(p); }
void operator delete[](void* p) noexcept { free(p); }
void operator delete(void* p, std::size_t) noexcept { free(p); }
void operator delete[](void* p, std::size_t) noexcept { free(p); }
void operator delete(void* p, std::align_val_t) noexcept { free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { free(p); }

// MRPT allocates its matrices and images through mrpt::aligned_malloc, which
// calls aligned_alloc and uses the result unchecked (a rawlog matrix of
// 0xffffffff x 4 floats crashed in memset). Under an AllocationLimit, a larger
// request throws std::bad_alloc like operator new, so the reader can name the
// malformed entry; otherwise this forwards to posix_memalign (C11 semantics).
extern "C" void* aligned_alloc(std::size_t align, std::size_t n) {
  if (navimpact::t_limit != 0 && n > navimpact::t_limit) navimpact::refuse(n);
  if (align < sizeof(void*)) align = sizeof(void*);
  void* p = nullptr;
  return posix_memalign(&p, align, n ? n : 1) == 0 ? p : nullptr;
}
