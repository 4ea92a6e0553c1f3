// FrameWriter (src/cli/frame_writer.h): octiso-render's writer thread. Every frame handed over is
// written, in order, by finish(); a failed write is rethrown to the renderer at its next call and
// nothing after it is written; dropping the writer with frames waiting neither hangs nor writes them;
// the latest frame written comes back, buffers and all, once.
#include <gtest/gtest.h>

#include <atomic>
#include <vector>

#include "cli/frame_writer.h"
#include "octiso/error.h"

namespace octiso::test {
namespace {

Frame frame_of_width(int w) {
    Frame f;
    f.width = w;
    f.height = 1;
    f.rgb.assign(size_t(3 * w), uint8_t(w));
    return f;
}

TEST(FrameWriter, EveryFrameIsWrittenInOrderWithItsTime) {
    std::vector<int> written;   // only the writer thread appends, finish() hands it back
    std::vector<double> seconds(5, -1.0);
    cli::FrameWriter writer;
    for (int k = 0; k < 5; ++k)
        writer.submit(frame_of_width(k + 1), [&](const Frame& f) {
            ASSERT_EQ(f.rgb.size(), size_t(3 * f.width));   // the frame arrives whole
            written.push_back(f.width);
        }, &seconds[size_t(k)]);
    writer.finish();
    EXPECT_EQ(written, (std::vector<int>{1, 2, 3, 4, 5}));
    for (double s : seconds) EXPECT_GE(s, 0.0);
}

TEST(FrameWriter, TheLatestWrittenFrameComesBackWithItsBuffersOnce) {
    cli::FrameWriter writer;
    EXPECT_EQ(writer.take_written().width, 0) << "nothing written yet: an empty frame";
    std::vector<double> seconds(2, 0.0);
    Frame first = frame_of_width(7), second = frame_of_width(9);
    const uint8_t* second_pixels = second.rgb.data();
    writer.submit(std::move(first), [](const Frame&) {}, &seconds[0]);
    writer.submit(std::move(second), [](const Frame&) {}, &seconds[1]);
    writer.finish();
    Frame back = writer.take_written();
    EXPECT_EQ(back.width, 9) << "the latest written, the earlier one freed";
    EXPECT_EQ(back.rgb.data(), second_pixels) << "its buffers moved back, not copied";
    EXPECT_EQ(back.rgb, std::vector<uint8_t>(27, uint8_t(9)));
    EXPECT_EQ(writer.take_written().width, 0) << "taken once";
}

TEST(FrameWriter, AFailedWriteIsRethrownAndNothingAfterItIsWritten) {
    std::vector<int> written;
    std::vector<double> seconds(4, 0.0);
    cli::FrameWriter writer;
    const auto write = [&](const Frame& f) {
        if (f.width == 2) throw Error("frame-2.png", "cannot write");
        written.push_back(f.width);
    };
    bool thrown = false;
    try {
        for (int k = 0; k < 4; ++k) writer.submit(frame_of_width(k + 1), write, &seconds[size_t(k)]);
        writer.finish();
    } catch (const Error& e) {
        thrown = true;
        EXPECT_NE(std::string(e.what()).find("frame-2.png"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(thrown);
    EXPECT_THROW(writer.finish(), Error) << "the failure stays";
    EXPECT_EQ(written.front(), 1);
    for (int w : written) EXPECT_LT(w, 2) << "frame " << w << " written after the failure";
}

TEST(FrameWriter, DroppedWithFramesWaitingItReturnsAndWritesNoneOfThemHalf) {
    // No finish(): the run failed elsewhere. What is checked is that the destructor returns (a
    // hang fails by ctest's timeout) and that every write that began also ended: frames are
    // dropped whole, never cut off in the middle.
    std::atomic<int> began{0}, ended{0};
    std::vector<double> seconds(3, 0.0);
    {
        cli::FrameWriter writer;
        for (int k = 0; k < 3; ++k)
            writer.submit(frame_of_width(k + 1), [&](const Frame&) { ++began; ++ended; }, &seconds[size_t(k)]);
    }
    EXPECT_EQ(began.load(), ended.load());
}

}  // namespace
}  // namespace octiso::test
