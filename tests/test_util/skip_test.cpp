// OCTISO_SKIP must turn into a failure under OCTISO_REQUIRE_ALL=1: that is what keeps a missing tool
// or data file from passing CI as a skip.
#include <cstdlib>
#include <optional>
#include <string>

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include "test_util/skip.h"

namespace octiso::test {
namespace {

void skip_because_missing() { OCTISO_SKIP("/no/such/tool not built"); }

TEST(OctisoSkip, FailsWhenEveryTestIsRequired) {
    const char* before = std::getenv("OCTISO_REQUIRE_ALL");
    const std::optional<std::string> saved = before ? std::optional<std::string>(before) : std::nullopt;
    ::setenv("OCTISO_REQUIRE_ALL", "1", 1);
    EXPECT_TRUE(skips_must_fail());
    EXPECT_FATAL_FAILURE(skip_because_missing(), "/no/such/tool not built (OCTISO_REQUIRE_ALL is set: a skip fails)");
    ::setenv("OCTISO_REQUIRE_ALL", "0", 1);
    EXPECT_FALSE(skips_must_fail());
    if (saved) ::setenv("OCTISO_REQUIRE_ALL", saved->c_str(), 1);
    else ::unsetenv("OCTISO_REQUIRE_ALL");
}

}  // namespace
}  // namespace octiso::test
