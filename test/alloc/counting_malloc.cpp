// Counts heap allocations by wrapping glibc's allocator. Every path to the heap
// (operator new, Eigen's aligned_malloc, std containers) ends in one of these.
#include <cstddef>

#include "counting_malloc.hpp"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);

void* malloc(std::size_t size) {
  ++zwang::testing::allocation_count;
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) {
  ++zwang::testing::allocation_count;
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t size) {
  ++zwang::testing::allocation_count;
  return __libc_realloc(p, size);
}
void* memalign(std::size_t alignment, std::size_t size) {
  ++zwang::testing::allocation_count;
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) {
  ++zwang::testing::allocation_count;
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) {
  ++zwang::testing::allocation_count;
  *out = __libc_memalign(alignment, size);
  return *out ? 0 : 12;  // ENOMEM
}
}

namespace zwang::testing {
volatile long allocation_count = 0;
}
