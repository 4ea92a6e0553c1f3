// What every octiso-bench subcommand shares: self-registration (one .cpp per question adds
// itself), a printed table, the JSON result file (--results DIR; bench/results/ holds the committed ones), a PNG plot through Debian's
// /usr/bin/python3 + matplotlib, timers and peak RSS. Numbers are compared within one run, as
// ratios, because the machines are shared and noisy.
#pragma once

#include <chrono>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "cli/common/cli.h"
#include "cli/common/json.h"
#include "util/process_memory.h"   // peak_rss_bytes, current_rss_bytes, mapped_resident_bytes

namespace octiso::bench {

using BenchFn = int (*)(cli::Args& args);
/// Called from a static initialiser in each bench/*.cpp: `static const bool kReg = register_bench(...)`.
bool register_bench(const char* name, const char* summary, BenchFn run);

/// A text table: set the header, add rows of already formatted cells, print aligned.
class Table {
public:
    explicit Table(std::vector<std::string> header) : header_(std::move(header)) {}
    void add(std::vector<std::string> row) { rows_.push_back(std::move(row)); }
    void print(std::ostream& out) const;
    /// The same table as GitHub markdown (for BENCHMARKS.md).
    void print_markdown(std::ostream& out) const;

private:
    std::vector<std::string> header_;
    std::vector<std::vector<std::string>> rows_;
};

std::string fmt(double v, int precision = 3);   ///< fixed for moderate values, scientific otherwise

/// --results DIR (created if missing), else $TMPDIR/octiso-bench-results: benchmarks write into the
/// source tree only when asked (`--results bench/results`).
std::string results_dir(cli::Args& args);
/// Writes DIR/NAME.json through `fill` (which writes one object) and returns the path.
std::string write_json(const std::string& dir, const std::string& name, const std::function<void(cli::JsonWriter&)>& fill);
/// Runs bench/plot.py KIND JSON PNG with /usr/bin/python3; returns false (and says so) if that fails.
bool plot(const std::string& kind, const std::string& json_path, const std::string& png_path);

double seconds_since(std::chrono::steady_clock::time_point t0);
/// Median wall seconds of `repeats` calls of fn (after one warm-up call).
double median_seconds(int repeats, const std::function<void()>& fn);

/// CPU seconds of the calling thread: a one-thread frame timed this way does not count the time
/// the scheduler gives other processes on a shared machine.
double thread_cpu_seconds();
/// The isovalue every benchmark uses for a dataset unless --iso says otherwise: half-integers on
/// u8 data, so no voxel lies exactly on the surface and no method is judged on a tie.
/// plume 40.5, mixing 127.5, sphere 20.5, anything else (ch2 MRI: the white/grey matter boundary) 80.5.
double default_isovalue(const std::string& dataset);

/// Machine line for the reports: CPU model, cores, compiler.
std::string machine_description();

}  // namespace octiso::bench
