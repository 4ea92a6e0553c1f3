// view/coalescer.h: one render in flight; of the requests waiting meanwhile only the newest is
// rendered, every older one is answered superseded; an exception frees the slot. Threads are
// synchronised on the Coalescer's own counts, never on sleeps, so the outcome is exact.
#include <gtest/gtest.h>

#include <atomic>
#include <future>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "view/coalescer.h"

namespace octiso::view {
namespace {

using C = Coalescer<int, int>;

/// A render that blocks until released, so a test can hold a render in flight.
struct Gate {
    std::promise<void> open;
    std::shared_future<void> opened = open.get_future().share();
};

TEST(ViewCoalescer, AloneARequestIsRendered) {
    C c;
    EXPECT_EQ(c.run(7, [](int x) { return x * 2; }), std::optional<int>(14));
    const C::Counts n = c.counts();
    EXPECT_FALSE(n.in_flight);
    EXPECT_EQ(n.issued, 1u);
    EXPECT_EQ(n.rendered, 1u);
    EXPECT_EQ(n.superseded, 0u);
}

TEST(ViewCoalescer, NewestWaitingRequestWinsOlderOnesAreSuperseded) {
    C c;
    Gate gate;
    std::vector<int> rendered;   // written only inside renders, which never overlap
    auto render = [&](int x) {
        rendered.push_back(x);
        if (x == 1) gate.opened.wait();
        return x * 10;
    };
    auto first = std::async(std::launch::async, [&] { return c.run(1, render); });
    c.wait_until([](const C::Counts& n) { return n.in_flight; });
    auto second = std::async(std::launch::async, [&] { return c.run(2, render); });
    c.wait_until([](const C::Counts& n) { return n.issued == 2; });
    auto third = std::async(std::launch::async, [&] { return c.run(3, render); });
    // The second is answered as soon as the third arrives, while the first still renders.
    EXPECT_EQ(second.get(), std::nullopt);
    EXPECT_TRUE(c.counts().in_flight);
    EXPECT_EQ(c.counts().rendered, 0u);
    auto fourth = std::async(std::launch::async, [&] { return c.run(4, render); });
    EXPECT_EQ(third.get(), std::nullopt);
    gate.open.set_value();
    EXPECT_EQ(first.get(), std::optional<int>(10));
    EXPECT_EQ(fourth.get(), std::optional<int>(40));
    EXPECT_EQ(rendered, (std::vector<int>{1, 4}));
    const C::Counts n = c.counts();
    EXPECT_EQ(n.issued, 4u);
    EXPECT_EQ(n.rendered, 2u);
    EXPECT_EQ(n.superseded, 2u);
    EXPECT_FALSE(n.in_flight);
}

TEST(ViewCoalescer, RendersNeverOverlap) {
    C c;
    std::atomic<int> inside{0}, worst{0};
    auto render = [&](int x) {
        const int now = ++inside;
        int w = worst.load();
        while (now > w && !worst.compare_exchange_weak(w, now)) {}
        std::this_thread::yield();
        --inside;
        return x;
    };
    std::vector<std::thread> threads;
    std::atomic<int> answered{0};
    for (int t = 0; t < 8; ++t)
        threads.emplace_back([&, t] {
            for (int i = 0; i < 200; ++i) {
                c.run(t * 1000 + i, render);
                ++answered;
            }
        });
    for (auto& t : threads) t.join();
    EXPECT_EQ(worst.load(), 1);
    EXPECT_EQ(answered.load(), 1600);
    const C::Counts n = c.counts();
    EXPECT_EQ(n.rendered + n.superseded, 1600u);
}

TEST(ViewCoalescer, AThrowingRenderFreesTheSlot) {
    C c;
    EXPECT_THROW(c.run(1, [](int) -> int { throw std::runtime_error("bad isovalue"); }), std::runtime_error);
    EXPECT_FALSE(c.counts().in_flight);
    EXPECT_EQ(c.run(2, [](int x) { return x; }), std::optional<int>(2));
}

}  // namespace
}  // namespace octiso::view
