// Counts heap allocations by replacing the global operator new and delete (malloc and free
// underneath). Include in exactly one translation unit of a benchmark executable.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <new>

namespace navbus::bench {
inline std::atomic<std::uint64_t> g_allocations{0};
}  // namespace navbus::bench

// GCC 12 sees the inlined malloc/free pair behind these replacements as a mismatch.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

void* operator new(std::size_t n) {
  ++navbus::bench::g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
