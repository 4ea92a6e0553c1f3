// The image files of a series or an orbit are written on a thread of their own while the next
// frame renders (issue 12). Encoding is serial: a 1024^2 PNG with its depth and normal EXRs took
// 60-80 ms of one core per frame (ch2better, octiso-render --json "write"), more than a 16-thread
// trace of it, so written in line it bounded many-core batch rendering. At most one frame waits
// while another is written, and the renderer allocates a frame only when no written one has come
// back (take_written), so a series holds three frames at most, as before the frames came back.
#pragma once

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "octiso/frame.h"

namespace octiso::cli {

class FrameWriter {
public:
    /// Writes `frame` by calling write(frame) on the writer thread.
    using Write = std::function<void(const Frame&)>;

    FrameWriter();
    /// Stops after the write in progress; frames still waiting are dropped (the run failed).
    ~FrameWriter();
    FrameWriter(const FrameWriter&) = delete;
    FrameWriter& operator=(const FrameWriter&) = delete;

    /// Hands `frame` over: returns once the writer has taken the frame before it. The seconds the
    /// write takes are stored into *seconds (which must stay valid until finish()). Rethrows the
    /// failure of an earlier write (its Error names the file), after which nothing more is written.
    void submit(Frame frame, Write write, double* seconds);
    /// Waits until every frame handed over is written; rethrows the first failure.
    void finish();
    /// The latest frame written, its buffers kept for the next frame to render into (an empty
    /// Frame if none is back yet). A fresh 512^2 frame's buffers cost page faults and zeroing
    /// on every frame of a series; a returned one is resized in place (BENCHMARKS "Frame buffers:
    /// reuse in a series and huge pages").
    Frame take_written();

private:
    struct Job {
        Frame frame;
        Write write;
        double* seconds = nullptr;
    };
    void run();
    void rethrow_failure();   // with the mutex held

    std::mutex mutex_;
    std::condition_variable changed_;
    std::optional<Job> waiting_;   // the next frame to write
    std::optional<Frame> written_; // the latest frame written, for take_written()
    bool busy_ = false, stop_ = false;
    std::exception_ptr failure_;
    std::thread thread_;
};

}  // namespace octiso::cli
