// FrameWriter (frame_writer.h): one thread, one waiting slot, the first failure kept.
#include "cli/frame_writer.h"

#include <chrono>

namespace octiso::cli {

FrameWriter::FrameWriter() : thread_([this] { run(); }) {}

FrameWriter::~FrameWriter() {
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
        waiting_.reset();
    }
    changed_.notify_all();
    thread_.join();
}

void FrameWriter::rethrow_failure() {
    if (failure_) std::rethrow_exception(failure_);
}

void FrameWriter::submit(Frame frame, Write write, double* seconds) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return !waiting_ || failure_; });
    rethrow_failure();
    waiting_ = Job{std::move(frame), std::move(write), seconds};
    lock.unlock();
    changed_.notify_all();
}

void FrameWriter::finish() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return (!waiting_ && !busy_) || failure_; });
    rethrow_failure();
}

Frame FrameWriter::take_written() {
    const std::lock_guard<std::mutex> lock(mutex_);
    Frame frame;
    if (written_) frame = std::move(*written_), written_.reset();
    return frame;
}

void FrameWriter::run() {
    for (;;) {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return waiting_ || stop_; });
        if (stop_) return;
        Job job = std::move(*waiting_);
        waiting_.reset();
        busy_ = true;
        lock.unlock();
        changed_.notify_all();   // the slot is free for the next frame
        std::exception_ptr failed;
        const auto t0 = std::chrono::steady_clock::now();
        try {
            job.write(job.frame);
        } catch (...) {
            failed = std::current_exception();
        }
        if (job.seconds) *job.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        lock.lock();
        busy_ = false;
        written_ = std::move(job.frame);
        if (failed && !failure_) failure_ = failed;
        if (failure_) waiting_.reset();   // nothing is written after a failure
        lock.unlock();
        changed_.notify_all();
    }
}

}  // namespace octiso::cli
