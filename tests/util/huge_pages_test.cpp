// util/huge_pages.h: the frame buffers' resize. What it must keep is plain std::vector behaviour
// (size, zeroed or filled fresh elements, a buffer large enough reused in place). The advice itself
// is read back from the kernel: /proc/self/smaps says per mapping whether it may take huge pages
// (THPeligible), which under THP's `madvise` mode (Debian's default) is exactly the advised
// 2 MiB pages, under `always` everything and under `never` nothing.
#include <gtest/gtest.h>

#include <sys/mman.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "util/huge_pages.h"

namespace octiso::test {
namespace {

constexpr uintptr_t kHugePage = uintptr_t(2) << 20;

/// THP's mode from sysfs ("always", "madvise", "never"), or "" on a kernel without THP.
std::string thp_mode() {
    std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string line;
    std::getline(in, line);
    const size_t open = line.find('['), close = line.find(']');
    return open == std::string::npos || close == std::string::npos ? "" : line.substr(open + 1, close - open - 1);
}

/// THPeligible of the mapping holding `address` in /proc/self/smaps; -1 if none says.
int thp_eligible(const void* address) {
    const uintptr_t a = reinterpret_cast<uintptr_t>(address);
    std::ifstream in("/proc/self/smaps");
    bool inside = false;
    for (std::string line; std::getline(in, line);) {
        uintptr_t lo = 0, hi = 0;
        char dash = 0;
        std::istringstream head(line);
        if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
            inside = lo <= a && a < hi;
            continue;
        }
        if (inside && line.rfind("THPeligible:", 0) == 0) return std::stoi(line.substr(12));
    }
    return -1;
}

/// What THPeligible must read for a page advised (or not) under this kernel's mode.
int expected_eligibility(bool advised) {
    const std::string mode = thp_mode();
    return mode == "always" || (mode == "madvise" && advised) ? 1 : 0;
}

/// The first whole 2 MiB page at or after p.
const void* first_huge_page(const void* p) {
    return reinterpret_cast<const void*>((reinterpret_cast<uintptr_t>(p) + kHugePage - 1) & ~(kHugePage - 1));
}

TEST(HugePages, AFreshBufferIsAdvisedAndZeroedAndALargeEnoughOneIsReusedInPlace) {
    std::vector<float> v;
    const size_t n = (size_t(5) << 20) / sizeof(float) + 3;   // over two whole 2 MiB pages, odd length
    resize_on_huge_pages(v, n);
    ASSERT_EQ(v.size(), n);
    EXPECT_TRUE(std::all_of(v.begin(), v.end(), [](float x) { return x == 0.0f; }));
    if (!thp_mode().empty()) {
        EXPECT_EQ(thp_eligible(first_huge_page(v.data())), expected_eligibility(true)) << thp_mode();
    }
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
    std::vector<float> filled(4, 1.0f);
    assign_on_huge_pages(filled, n, 2.5f);
    ASSERT_EQ(filled.size(), n);
    EXPECT_TRUE(std::all_of(filled.begin(), filled.end(), [](float x) { return x == 2.5f; }));
    const float* kept = filled.data();
    assign_on_huge_pages(filled, n / 3, -1.0f);
    EXPECT_EQ(filled.data(), kept);
    EXPECT_EQ(filled, std::vector<float>(n / 3, -1.0f));
}

TEST(HugePages, OnlyTheWholeHugePagesOfARangeAreAdvised) {
    advise_huge_pages(nullptr, 0);   // nothing to advise: returns
    advise_huge_pages(nullptr, size_t(8) << 20);
    const size_t bytes = size_t(8) << 20;
    void* map = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    ASSERT_NE(map, MAP_FAILED);
    auto* p = static_cast<uint8_t*>(map);
    const void* huge = first_huge_page(p + 4097);
    ASSERT_LE(static_cast<const uint8_t*>(huge) + kHugePage, p + bytes - 4096) << "8 MiB holds a whole 2 MiB page";
    const bool thp = !thp_mode().empty();
    if (thp) {
        EXPECT_EQ(thp_eligible(huge), expected_eligibility(false)) << thp_mode() << ", before any advice";
    }
    advise_huge_pages(p + 1, 100);               // inside one small page: no whole huge page
    if (thp) {
        EXPECT_EQ(thp_eligible(huge), expected_eligibility(false)) << thp_mode() << ", after advice elsewhere";
    }
    advise_huge_pages(p + 4097, bytes - 8193);   // unaligned at both ends: only its whole 2 MiB pages
    if (thp) {
        EXPECT_EQ(thp_eligible(huge), expected_eligibility(true)) << thp_mode();
        if (static_cast<const void*>(p) != huge) {   // the unaligned head before it stays unadvised
            EXPECT_EQ(thp_eligible(p), expected_eligibility(false)) << thp_mode();
        }
    } else {
        EXPECT_EQ(thp_eligible(huge), -1) << "no THP in sysfs, yet smaps reports eligibility";
    }
    std::fill(p, p + bytes, uint8_t(3));         // the memory stays ordinary memory
    EXPECT_EQ(p[0], 3);
    EXPECT_EQ(p[bytes - 1], 3);
    ::munmap(map, bytes);
}

}  // namespace
}  // namespace octiso::test
