#pragma once
// Replaces the global operator new/delete of the test executable that includes this header (include it
// in exactly one file of that executable) and counts every allocation, so a test can assert that a frame
// loop makes none.
#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <new>

namespace rivulet::test {
inline std::atomic<long> g_allocations{0};
inline long allocation_count() {
    return g_allocations.load(std::memory_order_relaxed);
}
// Out of line so GCC does not pair the inlined free() with a builtin operator new and warn.
[[gnu::noinline]] inline void release(void* p) noexcept {
    std::free(p);
}
}  // namespace rivulet::test

void* operator new(std::size_t n) {
    rivulet::test::g_allocations.fetch_add(1, std::memory_order_relaxed);
    if (void* p = std::malloc(n ? n : 1)) return p;
    throw std::bad_alloc();
}
void* operator new(std::size_t n, std::align_val_t a) {
    rivulet::test::g_allocations.fetch_add(1, std::memory_order_relaxed);
    const auto align = static_cast<std::size_t>(a);
    if (void* p = std::aligned_alloc(align, (std::max<std::size_t>(n, 1) + align - 1) / align * align))
        return p;
    throw std::bad_alloc();
}
// The nothrow forms too, so every allocation pairs with the delete below (sanitizers check the pairing).
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
    rivulet::test::g_allocations.fetch_add(1, std::memory_order_relaxed);
    return std::malloc(n ? n : 1);
}
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
    rivulet::test::g_allocations.fetch_add(1, std::memory_order_relaxed);
    const auto align = static_cast<std::size_t>(a);
    return std::aligned_alloc(align, (std::max<std::size_t>(n, 1) + align - 1) / align * align);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
    rivulet::test::release(p);
}
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept {
    rivulet::test::release(p);
}
void operator delete(void* p) noexcept {
    rivulet::test::release(p);
}
void operator delete(void* p, std::size_t) noexcept {
    rivulet::test::release(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
    rivulet::test::release(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
    rivulet::test::release(p);
}
