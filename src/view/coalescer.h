// Coalescer: one render in flight, and of the requests that arrive meanwhile only the newest
// waits; each older waiting one is answered "superseded" at once (issue 20, "responsive under
// interaction"). A drag sends a request per mouse move; without this the server would render
// every one of them in turn and the picture would lag ever further behind the pointer.
//
// No worker thread: the caller whose request is next renders it on its own (HTTP handler)
// thread, so a reply never waits for a hand-off. Thread-safe; `render` runs outside the lock.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>

namespace octiso::view {

template <typename Request, typename Result>
class Coalescer {
public:
    /// Renders `request` with render(request) once no render is in flight and no newer request
    /// came in, and returns its result; returns nullopt (superseded) as soon as a newer request
    /// arrives while this one waits. Exceptions of `render` reach the caller; the next waiting
    /// request then proceeds.
    template <typename Render>
    std::optional<Result> run(const Request& request, Render&& render) {
        std::unique_lock lock(mutex_);
        const uint64_t ticket = ++last_ticket_;   // the newest ticket is the only one that may wait
        changed_.notify_all();                    // older waiters see they lost
        changed_.wait(lock, [&] { return ticket != last_ticket_ || !in_flight_; });
        if (ticket != last_ticket_) {
            ++superseded_;
            changed_.notify_all();
            return std::nullopt;
        }
        in_flight_ = true;
        lock.unlock();
        struct Done {   // clears in_flight_ also when render throws
            Coalescer& c;
            ~Done() {
                std::lock_guard relock(c.mutex_);
                c.in_flight_ = false;
                ++c.rendered_;
                c.changed_.notify_all();
            }
        } done{*this};
        return std::optional<Result>(render(request));
    }

    /// For tests and the status line: whether a render runs now, how many requests were issued
    /// (tickets), rendered and superseded so far.
    struct Counts {
        bool in_flight = false;
        uint64_t issued = 0, rendered = 0, superseded = 0;
    };
    Counts counts() const {
        std::lock_guard lock(mutex_);
        return {in_flight_, last_ticket_, rendered_, superseded_};
    }

    /// Blocks until `pred(counts())` holds (tests: "the second request is waiting now").
    template <typename Pred>
    void wait_until(Pred&& pred) const {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [&] { return pred(Counts{in_flight_, last_ticket_, rendered_, superseded_}); });
    }

private:
    mutable std::mutex mutex_;
    mutable std::condition_variable changed_;
    uint64_t last_ticket_ = 0, rendered_ = 0, superseded_ = 0;
    bool in_flight_ = false;
};

}  // namespace octiso::view
