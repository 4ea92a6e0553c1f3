// util/huge_pages.h: the frame buffers' resize. What it must keep is plain std::vector behaviour
// (size, zeroed fresh elements, a buffer large enough reused in place); the huge-page advice is a
// hint the kernel may ignore, so it is checked only to be harmless on any range.
#include <gtest/gtest.h>

#include <sys/mman.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "util/huge_pages.h"

namespace octiso::test {
namespace {

TEST(HugePages, AFreshBufferHasItsSizeAndZeroesAndALargeEnoughOneIsReusedInPlace) {
    std::vector<float> v;
    const size_t n = (size_t(5) << 20) / sizeof(float) + 3;   // over two whole 2 MiB pages, odd length
    resize_on_huge_pages(v, n);
    ASSERT_EQ(v.size(), n);
    EXPECT_TRUE(std::all_of(v.begin(), v.end(), [](float x) { return x == 0.0f; }));
    std::fill(v.begin(), v.end(), 7.0f);
    const float* before = v.data();
    resize_on_huge_pages(v, n / 2);
    EXPECT_EQ(v.data(), before) << "a smaller frame renders into the same buffer";
    EXPECT_EQ(v.size(), n / 2);
    resize_on_huge_pages(v, n);
    EXPECT_EQ(v.data(), before) << "and so does one of the old size, within capacity";
    resize_on_huge_pages(v, 2 * n);
    ASSERT_EQ(v.size(), 2 * n);
    EXPECT_TRUE(std::all_of(v.begin(), v.end(), [](float x) { return x == 0.0f; }))
        << "a larger frame gets a fresh buffer: what it does not keep it zeroes";
    resize_on_huge_pages(v, 0);
    EXPECT_TRUE(v.empty());
    std::vector<uint8_t> small;
    resize_on_huge_pages(small, 5);   // under one huge page: plain resize
    EXPECT_EQ(small, std::vector<uint8_t>(5, 0));
}

TEST(HugePages, AdviceOnAnyRangeIsHarmless) {
    advise_huge_pages(nullptr, 0);
    advise_huge_pages(nullptr, size_t(8) << 20);
    const size_t bytes = size_t(8) << 20;
    void* map = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    ASSERT_NE(map, MAP_FAILED);
    auto* p = static_cast<uint8_t*>(map);
    advise_huge_pages(p + 1, 100);               // inside one small page
    advise_huge_pages(p + 4097, bytes - 8193);   // unaligned at both ends: only whole 2 MiB pages
    advise_huge_pages(p, bytes);
    std::fill(p, p + bytes, uint8_t(3));         // the memory stays ordinary memory
    EXPECT_EQ(p[0], 3);
    EXPECT_EQ(p[bytes - 1], 3);
    ::munmap(map, bytes);
}

}  // namespace
}  // namespace octiso::test
