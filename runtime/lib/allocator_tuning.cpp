#include "runtime/lib/allocator_tuning.h"

#include <malloc.h>

namespace rivulet {

void keep_freed_memory_for_reuse() {
    constexpr int kMiB = 1 << 20;
    mallopt(M_MMAP_THRESHOLD, 512 * kMiB);   // large blocks from the heap, not fresh mappings
    mallopt(M_TRIM_THRESHOLD, 1024 * kMiB);  // keep freed heap memory instead of trimming it
    mallopt(M_TOP_PAD, 64 * kMiB);           // grow the heap in large steps
}

}  // namespace rivulet
