#pragma once

namespace zwang::testing {
// Incremented by every malloc/calloc/realloc/aligned allocation in the process.
extern volatile long allocation_count;

// Allocations made while running f.
template <class F>
long allocationsDuring(F&& f) {
  const long before = allocation_count;
  f();
  return allocation_count - before;
}
}  // namespace zwang::testing
