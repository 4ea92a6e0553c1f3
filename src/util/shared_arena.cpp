// shared_arena (shared_arena.h): a map from thread count to a never-destroyed arena. Never
// destroyed, so that no arena is torn down while a static object's destructor might still use it.
#include "util/shared_arena.h"

#include <map>
#include <memory>
#include <mutex>

namespace octiso {

tbb::task_arena* shared_arena(int threads) {
    if (threads <= 0) return nullptr;
    static std::mutex mutex;
    static auto* arenas = new std::map<int, std::unique_ptr<tbb::task_arena>>();
    const std::lock_guard<std::mutex> lock(mutex);
    std::unique_ptr<tbb::task_arena>& a = (*arenas)[threads];
    if (!a) a = std::make_unique<tbb::task_arena>(threads);
    return a.get();
}

}  // namespace octiso
