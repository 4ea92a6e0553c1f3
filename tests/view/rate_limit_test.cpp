// view/rate_limit.h: a token bucket driven by explicit times, so every count is exact.
#include <gtest/gtest.h>

#include "view/rate_limit.h"

namespace octiso::view {
namespace {

TEST(ViewRateLimit, BurstThenRefillAtTheRate) {
    RateLimit r(4, 2);   // 4 at once, then 2 per second
    for (int i = 0; i < 4; ++i) EXPECT_TRUE(r.admit(10.0)) << i;
    EXPECT_FALSE(r.admit(10.0));
    EXPECT_FALSE(r.admit(10.25));   // half a token
    EXPECT_TRUE(r.admit(10.5));     // one token since 10.0
    EXPECT_FALSE(r.admit(10.5));
    EXPECT_TRUE(r.admit(11.0));
    // A long pause refills only to capacity.
    int admitted = 0;
    for (int i = 0; i < 10; ++i) admitted += r.admit(1000.0);
    EXPECT_EQ(admitted, 4);
}

TEST(ViewRateLimit, TimeGoingBackwardsAddsNothing) {
    RateLimit r(1, 1);
    EXPECT_TRUE(r.admit(5.0));
    EXPECT_FALSE(r.admit(1.0));
    EXPECT_FALSE(r.admit(5.5));
    EXPECT_TRUE(r.admit(6.0));
}

}  // namespace
}  // namespace octiso::view
