// One TBB task arena per thread count for the whole process (issue 12). A frame's passes (the
// tile loop, deferred shading, the look's secondary rays) and every Renderer of a series used to
// create arenas of their own: TBB's workers stay in the arena they last served and move to a new
// one only lazily, so a pass in a fresh arena right after the trace ran mostly on its calling
// thread (octiso-render --threads 2, ch2better 1024^2, orbit frames: deferred shading in rows in
// parallel 16-20 ms in its own arena, 12-16 ms in the Renderer's, 22-28 ms on one thread;
// BENCHMARKS.md "Many-core"). Sharing one arena per count keeps the workers where the work is.
#pragma once

#include <tbb/task_arena.h>

namespace octiso {

/// The process's arena of `threads` threads, created on first use and kept until exit; null for
/// threads <= 0 (the caller runs in its own arena: all cores, or whatever it is inside). Two
/// callers of one count share its threads, as --threads N means N in all. Thread-safe.
tbb::task_arena* shared_arena(int threads);

/// f() inside shared_arena(threads), or directly for threads <= 0.
template <class F> decltype(auto) in_shared_arena(int threads, F&& f) {
    tbb::task_arena* arena = shared_arena(threads);
    return arena ? arena->execute(f) : f();
}

}  // namespace octiso
