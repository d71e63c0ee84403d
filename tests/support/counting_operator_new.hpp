// Every heap allocation of a binary, counted: the replaceable global allocation functions
// ([new.delete]) all on malloc/free, each new adding one to backlash::testing::heap_allocations.
//
// Include this header in exactly ONE translation unit of a test or benchmark binary (a
// replacement function is defined once per program and may not be inline).  The library's own
// allocations are counted too, since the replacement is program-wide.
//
// Every form is replaced, not only operator new(size): the library (and libstdc++, e.g.
// std::inplace_merge's temporary buffer through operator new(size, nothrow)) allocates through the
// nothrow and aligned forms as well, and a form left unreplaced would pair the runtime's new with
// this file's free; AddressSanitizer stops on that as an alloc-dealloc mismatch.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

namespace backlash::testing {
inline std::atomic<long> heap_allocations{0};

namespace counting_new_detail {
inline void* allocate(std::size_t size) noexcept {
  heap_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size == 0 ? 1 : size);
}
inline void* allocate_aligned(std::size_t size, std::align_val_t alignment) noexcept {
  heap_allocations.fetch_add(1, std::memory_order_relaxed);
  const auto a = static_cast<std::size_t>(alignment);
  const std::size_t rounded = (size == 0 ? a : (size + a - 1) / a * a);  // aligned_alloc wants a multiple
  return std::aligned_alloc(a, rounded);
}
}  // namespace counting_new_detail
}  // namespace backlash::testing

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"  // the counting operator new is malloc, its delete free
void* operator new(std::size_t size) {
  if (void* p = backlash::testing::counting_new_detail::allocate(size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return backlash::testing::counting_new_detail::allocate(size);
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return backlash::testing::counting_new_detail::allocate(size);
}
void* operator new(std::size_t size, std::align_val_t alignment) {
  if (void* p = backlash::testing::counting_new_detail::allocate_aligned(size, alignment)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size, std::align_val_t alignment) { return operator new(size, alignment); }
void* operator new(std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return backlash::testing::counting_new_detail::allocate_aligned(size, alignment);
}
void* operator new[](std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return backlash::testing::counting_new_detail::allocate_aligned(size, alignment);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
#pragma GCC diagnostic pop
