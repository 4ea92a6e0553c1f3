// RateLimit: a token bucket over all requests of the server (issue 20: a bound on the request
// rate). Burst `capacity` requests, refilled at `per_second`; a request finding the bucket empty
// is refused (429), not queued, so a flood costs the server a header parse per request and no
// render. Time is passed in, so tests can drive it exactly. Thread-safe.
#pragma once

#include <algorithm>
#include <mutex>

namespace octiso::view {

class RateLimit {
public:
    /// capacity >= 1 tokens, per_second > 0. The bucket starts full.
    RateLimit(double capacity, double per_second) : capacity_(capacity), per_second_(per_second), tokens_(capacity) {}

    /// Takes one token at time `now_s` (seconds on any monotonic clock, never decreasing between
    /// calls; a decrease is treated as no time passing). True if the request may proceed.
    bool admit(double now_s) {
        std::lock_guard lock(mutex_);
        if (started_ && now_s > last_s_) tokens_ = std::min(capacity_, tokens_ + (now_s - last_s_) * per_second_);
        if (!started_ || now_s > last_s_) last_s_ = now_s;
        started_ = true;
        if (tokens_ < 1.0) return false;
        tokens_ -= 1.0;
        return true;
    }

private:
    std::mutex mutex_;
    double capacity_, per_second_, tokens_;
    double last_s_ = 0;
    bool started_ = false;
};

}  // namespace octiso::view
