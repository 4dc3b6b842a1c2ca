// Counts the heap allocations of the whole process (OpenCV's included) while
// g_counting is on: glibc lets a program replace malloc and friends, and these forward to
// glibc's own. Include it in ONE file of a program (it defines malloc); under
// AddressSanitizer, which owns malloc, nothing is replaced and MPD_OWN_MALLOC is 0.
// Used by benchmark_tracker_floor and test_tracker_allocations.
#pragma once

#include <atomic>
#include <cstddef>

// AddressSanitizer owns malloc (gcc says so by __SANITIZE_ADDRESS__, clang by a feature).
#if defined(__SANITIZE_ADDRESS__)
#define MPD_OWN_MALLOC 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MPD_OWN_MALLOC 0
#endif
#endif
#ifndef MPD_OWN_MALLOC
#define MPD_OWN_MALLOC 1
#endif

// The counters exist either way (they stay 0 under AddressSanitizer).
namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0}, g_bytes{0};
}  // namespace

#if MPD_OWN_MALLOC
extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* __libc_memalign(size_t, size_t);
void __libc_free(void*);
}
namespace {
void count(size_t bytes) {
  if (!g_counting.load(std::memory_order_relaxed)) return;
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  g_bytes.fetch_add(static_cast<long>(bytes), std::memory_order_relaxed);
}
}  // namespace
extern "C" {
void* malloc(size_t n) {
  count(n);
  return __libc_malloc(n);
}
void* calloc(size_t n, size_t size) {
  count(n * size);
  return __libc_calloc(n, size);
}
void* realloc(void* p, size_t n) {
  count(n);
  return __libc_realloc(p, n);
}
void* memalign(size_t alignment, size_t n) {
  count(n);
  return __libc_memalign(alignment, n);
}
void* aligned_alloc(size_t alignment, size_t n) {
  count(n);
  return __libc_memalign(alignment, n);
}
int posix_memalign(void** out, size_t alignment, size_t n) {
  count(n);
  *out = __libc_memalign(alignment, n);
  return *out ? 0 : 12;  // ENOMEM
}
void free(void* p) { __libc_free(p); }
}
#endif
