// advise_huge_pages (huge_pages.h): madvise on the whole 2 MiB pages of a range.
#include "util/huge_pages.h"

#include <sys/mman.h>

#include <cstdint>

namespace octiso {

void advise_huge_pages(void* data, size_t bytes) {
    constexpr uintptr_t kHuge = uintptr_t(2) << 20;
    const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
    const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHuge - 1);
    if (data == nullptr || end <= begin) return;
    (void)::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);   // advice: errors change nothing
}

}  // namespace octiso
