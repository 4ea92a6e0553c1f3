// ProgressLine (src/cli/common/progress.h): what it draws, that it draws nothing when disabled
// (stderr not a terminal), that it waits for its delay, and that finish() ends the line once.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "cli/common/progress.h"

namespace octiso::cli {
namespace {

std::string read_all(std::FILE* f) {
    std::fflush(f);
    std::rewind(f);
    std::string s;
    char buf[4096];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
    return s;
}

TEST(ProgressLine, TextHasBarPercentDetailAndEta) {
    EXPECT_EQ(ProgressLine::text(1, 4, 3.0, "1/4 frames"), "[######                  ]  25%  1/4 frames  ETA 9 s");
    EXPECT_EQ(ProgressLine::text(4, 4, 12.0, ""), "[########################] 100%  12.0 s");
    EXPECT_EQ(ProgressLine::text(0, 4, 0.0, ""), "[                        ]   0%");
}

TEST(ProgressLine, DisabledWritesNothing) {
    std::FILE* f = std::tmpfile();
    ASSERT_NE(f, nullptr);
    {
        ProgressLine p(f, false, 0.0);
        for (int i = 1; i <= 3; ++i) p.update(i, 3, "x");
        EXPECT_FALSE(p.shown());
    }
    EXPECT_EQ(read_all(f), "");
    std::fclose(f);
}

TEST(ProgressLine, EnabledRedrawsInPlaceAndEndsTheLineOnce) {
    std::FILE* f = std::tmpfile();
    ASSERT_NE(f, nullptr);
    {
        ProgressLine p(f, true, 0.0);
        p.update(1, 2, "a");
        p.update(2, 2, "b");   // the last update is always drawn, however soon
        p.finish();
        p.finish();
    }
    const std::string s = read_all(f);
    EXPECT_EQ(s.front(), '\r');
    EXPECT_NE(s.find("50%  a"), std::string::npos) << s;
    EXPECT_NE(s.find("100%  b"), std::string::npos) << s;
    EXPECT_EQ(std::count(s.begin(), s.end(), '\n'), 1) << s;
    EXPECT_EQ(s.back(), '\n');
    std::fclose(f);
}

TEST(ProgressLine, NothingBeforeTheDelay) {
    std::FILE* f = std::tmpfile();
    ASSERT_NE(f, nullptr);
    {
        ProgressLine p(f, true, 3600.0);
        p.update(1, 3, "early");
    }
    EXPECT_EQ(read_all(f), "");
    std::fclose(f);
}

}  // namespace
}  // namespace octiso::cli
