#pragma once
// Replaces the global operator new/delete of the test executable that includes this header (include it
// in exactly one file of that executable) and counts every allocation, so a test can assert that a frame
// loop makes none. Allocations oneTBB itself makes are not counted: its per-thread pools of task objects
// grow whenever more tasks are in flight than ever before, which depends on how the threads happened to
// be scheduled (a frame loop with a video encoder beside it failed one run in two on that alone), and
// stop growing at their peak; what the frame's own code allocates is counted wherever it runs.
#include <link.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>

namespace rivulet::test {
inline std::atomic<long> g_allocations{0};
inline long allocation_count() {
    return g_allocations.load(std::memory_order_relaxed);
}
// oneTBB's code in memory (empty where no libtbb.so is loaded: then everything is counted), found once:
// operator new runs for every allocation, Mesa's shader compiler's included.
struct CodeRange {
    std::uintptr_t lo = 0, hi = 0;
};
inline CodeRange tbb_code() noexcept {
    static const CodeRange range = [] {
        CodeRange r;
        dl_iterate_phdr(
            [](dl_phdr_info* info, std::size_t, void* data) {
                if (info->dlpi_name == nullptr || std::strstr(info->dlpi_name, "libtbb.so") == nullptr)
                    return 0;
                for (int k = 0; k < info->dlpi_phnum; ++k) {
                    const ElfW(Phdr)& ph = info->dlpi_phdr[k];
                    if (ph.p_type != PT_LOAD || (ph.p_flags & PF_X) == 0) continue;
                    auto* out = static_cast<CodeRange*>(data);
                    out->lo = info->dlpi_addr + ph.p_vaddr, out->hi = out->lo + ph.p_memsz;
                    return 1;
                }
                return 0;
            },
            &r);
        return r;
    }();
    return range;
}
[[gnu::always_inline]] inline void count(const void* caller) noexcept {
    const CodeRange tbb = tbb_code();
    const auto at = reinterpret_cast<std::uintptr_t>(caller);
    if (at < tbb.lo || at >= tbb.hi) g_allocations.fetch_add(1, std::memory_order_relaxed);
}
// Out of line so GCC does not pair the inlined free() with a builtin operator new and warn.
[[gnu::noinline]] inline void release(void* p) noexcept {
    std::free(p);
}
}  // namespace rivulet::test

void* operator new(std::size_t n) {
    rivulet::test::count(__builtin_return_address(0));
    if (void* p = std::malloc(n ? n : 1)) return p;
    throw std::bad_alloc();
}
void* operator new(std::size_t n, std::align_val_t a) {
    rivulet::test::count(__builtin_return_address(0));
    const auto align = static_cast<std::size_t>(a);
    if (void* p = std::aligned_alloc(align, (std::max<std::size_t>(n, 1) + align - 1) / align * align))
        return p;
    throw std::bad_alloc();
}
// The nothrow forms too, so every allocation pairs with the delete below (sanitizers check the pairing).
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
    rivulet::test::count(__builtin_return_address(0));
    return std::malloc(n ? n : 1);
}
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
    rivulet::test::count(__builtin_return_address(0));
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
