// Large buffers that a frame writes whole (colour, depth, normal) on transparent huge pages.
// A fresh 1024^2 frame is 20 MiB of buffers: 5000 page faults of 4 KiB, which on this VM cost
// 44-47 ms, a third of a 2-thread trace of ch2better (octiso-render --json "other"); on 2 MiB
// pages 12-13 ms are left, and the frame takes 0.77-0.80 x the time. Where THP is off (enabled =
// never) the advice is a no-op and nothing else changes (BENCHMARKS "Frame buffers: reuse in a
// series and huge pages").
#pragma once

#include <cstddef>
#include <vector>

namespace octiso {

/// Asks the kernel (madvise MADV_HUGEPAGE) to back the 2 MiB-aligned pages inside
/// [data, data + bytes) with huge pages when they are first touched. Ranges under 2 MiB, and
/// kernels without THP, are left alone. Never fails: it is advice.
void advise_huge_pages(void* data, size_t bytes);

/// Makes v's capacity at least n: a fresh allocation advised onto huge pages before any of it
/// is touched (the contents are not kept: for buffers every element of which is written next).
template <typename T> void reserve_on_huge_pages(std::vector<T>& v, size_t n) {
    if (v.capacity() >= n) return;
    std::vector<T> fresh;
    fresh.reserve(n);
    advise_huge_pages(fresh.data(), n * sizeof(T));
    v.swap(fresh);
}

/// v.resize(n) into reserve_on_huge_pages's buffer (the frame's traced buffers).
template <typename T> void resize_on_huge_pages(std::vector<T>& v, size_t n) {
    reserve_on_huge_pages(v, n);
    v.resize(n);
}

/// v.assign(n, value) into reserve_on_huge_pages's buffer, one pass over it: for buffers that
/// start at a fill value (the reference tracers' and the peers' frames, which write only hits).
template <typename T> void assign_on_huge_pages(std::vector<T>& v, size_t n, const T& value) {
    reserve_on_huge_pages(v, n);
    v.assign(n, value);
}

}  // namespace octiso
