// The conversion pipeline behind octiso-convert: volumes (one file, a list of files, a printf
// pattern over steps A..B, a synthetic generator, or the sparse-spheres field built directly as
// an octree) -> one .oct file. Every step is opened and checked against the first before
// anything is written; steps are then built and streamed into OctWriter one at a time, so memory
// stays near one input plus one octree. The caller gets a report to print; nothing here prints.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "octiso/build.h"
#include "octiso/oct_file.h"
#include "octiso/reader.h"
#include "octiso/synthetic.h"
#include "octiso/volume.h"

namespace octiso {

/// Where the steps of a conversion come from. Built by the factories below; immutable after.
class ConvertSource {
public:
    /// One input file (any format open_volume() reads), one step.
    static ConvertSource file(std::string path, RawOptions raw = {});
    /// Several input files, step i from paths[i] (at least one).
    static ConvertSource files(std::vector<std::string> paths, RawOptions raw = {});
    /// Steps first..last (inclusive) from `pattern` with one printf integer field (t_%03d.raw).
    /// Checks the pattern now: throws Error("--steps", ...) unless it holds exactly one %d field.
    static ConvertSource pattern(std::string pattern, long long first, long long last, RawOptions raw = {});
    /// A generator of synthetic.h, parsed from `spec` (NAME:N, NAME:NX,NY,NZ, plume-series:N,STEPS);
    /// `type` overrides the generator's type; raw.spacing / raw.origin override its placement
    /// (the other raw options do not apply). Throws Error("--synthetic", ...) for a bad spec.
    static ConvertSource synthetic(const std::string& spec, std::optional<ScalarType> type = {}, RawOptions raw = {});
    /// sparse-spheres:N (f32, N^3), built as an octree with no dense array (sparse_synthetic.h).
    static ConvertSource sparse_spheres(uint32_t n);

    /// What reports call the input: the file, the pattern, the first of a list, or the spec.
    const std::string& name() const { return name_; }
    uint32_t step_count() const;
    bool is_synthetic() const { return synthetic_.has_value(); }
    bool is_sparse_spheres() const { return sparse_n_ != 0; }
    uint32_t sparse_spheres_n() const { return sparse_n_; }
    /// The file of step i (list entry or expanded pattern); name() for a single file.
    std::string step_path(uint32_t i) const;
    /// Opens (or generates) step i, placement overrides applied. Throws Error naming the file.
    /// Not for sparse-spheres, which has no dense volume.
    LoadedVolume load(uint32_t i) const;
    /// The raw and placement flags every file step is opened with.
    const RawOptions& raw_options() const { return raw_; }

private:
    ConvertSource() = default;
    std::string name_;
    std::vector<std::string> list_;                 // several files: step i is list_[i]
    std::optional<std::array<long long, 2>> steps_; // a pattern over steps_[0]..steps_[1]
    std::optional<SyntheticSpec> synthetic_;
    std::optional<ScalarType> synthetic_type_;
    uint32_t sparse_n_ = 0;
    RawOptions raw_;
};

/// How much memory a conversion may use (issue 13, octiso-convert --memory).
struct MemoryOptions {
    /// --memory BYTES: the budget. Set: streamable input (raw files) is converted out of core,
    /// slab by slab, its node arrays spilled to temporaries beside the output once they outgrow
    /// the budget; input that must be read whole (VTK formats) is refused if it exceeds it.
    /// Unset: default_memory_budget(), and input is converted in memory when about twice its size
    /// fits that budget, out of core otherwise. Either way the file written is the same, byte for byte.
    std::optional<uint64_t> budget;
    uint32_t piece_side = 0;   ///< forces the out-of-core pieces' side (a power of two >= 4; tests); 0: from the budget
    bool force_streaming = false;   ///< out of core even without a budget (tests)
    bool force_in_memory = false;   ///< --in-memory: the whole-array path whatever the size (benchmarks)
    /// Called from the converting thread after each slab (out of core) or each step (in memory) with
    /// (bytes read so far, bytes in all, voxels built so far); for progress reports.
    std::function<void(uint64_t, uint64_t, uint64_t)> on_progress;
};

/// A quarter of the machine's physical memory (the default of --memory).
uint64_t default_memory_budget();

/// What one step cost and gave.
struct ConvertStepReport {
    std::string source;          ///< the step's file or synthetic name
    StepSizes sizes;             ///< nodes and scalar leaves per depth, section bytes
    double build_seconds = 0;    ///< the octree build alone
};

/// What a conversion did, for the tool's text and JSON reports (sizes in bytes, times in seconds).
struct ConvertReport {
    std::string input;           ///< ConvertSource::name()
    std::string output;
    VolumeFormat format = VolumeFormat::raw;   ///< of the first step
    ScalarType type = ScalarType::u8;
    Dims dims;
    Placement placement;
    int dmax = 0;
    uint32_t steps = 0;
    /// sparse-spheres: built directly as an octree; input_bytes, per_step timings and peak RSS
    /// are then not measured (0).
    bool built_directly = false;
    std::optional<std::array<double, 2>> iso_range;   ///< real values, as given
    double tolerance = 0.0;                            ///< real values, as given
    ValueScale value_scale;      ///< stored-to-real values of the source (NIfTI scl_slope/scl_inter)
    uint8_t flipped_axes = 0;    ///< source axes reversed at reading (volume.h)
    std::vector<std::string> warnings;   ///< readers' notes for the user (an oblique NIfTI)
    std::vector<ConvertStepReport> per_step;
    StepSizes total;             ///< sums over all steps, per depth and per section kind
    uint64_t input_bytes = 0;    ///< dense bytes of the first step times the step count
    uint64_t file_bytes = 0;
    double build_seconds = 0;    ///< sum of the steps' build_seconds
    double total_seconds = 0;    ///< the whole call, reading and writing included
    uint64_t peak_rss_bytes = 0; ///< the process's high-water mark when the file was finished
    int threads = 0;             ///< TBB's parallelism limit during the call
    bool streamed = false;       ///< converted out of core (MemoryOptions)
    uint64_t memory_budget = 0;  ///< the budget that applied
    uint32_t piece_side = 0;     ///< the out-of-core pieces' side, when streamed
    uint64_t bytes_read = 0;     ///< from the input files, when streamed
    uint64_t spilled_bytes = 0;  ///< node bytes that went through temporary files, when streamed
    /// In-memory conversion (issue 12): seconds of reading (or generating) the steps, of each
    /// build phase summed over the steps (build.h), and of appending the built steps to the file.
    /// Zero when streamed, whose slabs are read and built interleaved (build_seconds).
    double read_seconds = 0, write_seconds = 0;
    BuildPhases build_phases;
    /// Out of core, summed over the steps: the slabs (read and built, interleaved), the top above
    /// the pieces, the sections streamed into the file. Zero in memory.
    double slabs_seconds = 0, top_seconds = 0, sections_seconds = 0;

    double ratio() const { return input_bytes ? double(file_bytes) / double(input_bytes) : 0.0; }
    double mvoxels_per_second() const {
        return build_seconds > 0 ? double(dims.voxels()) * steps / build_seconds / 1e6 : 0.0;
    }
};

/// Converts `source` into the .oct file `output` with `options` (iso_range, tolerance, nan_as in
/// real values, mapped through the source's value scale; threads; source_name is set per step). Step 0 is opened and every other step checked
/// against it (dims, type, spacing and origin) before the output is created; a mismatch throws
/// Error(step file, ...) (exit 2) and writes nothing. Until the file is finished only a
/// temporary sibling exists, removed on any error. options.threads > 0 limits all TBB work
/// of the process to that many threads for the duration of the call (tbb::global_control).
/// `memory` chooses in-memory or out-of-core conversion (see MemoryOptions); a budget too small
/// for one slab is Error(input, "out of memory: ...") (exit 2) before the output is created.
ConvertReport convert(const ConvertSource& source, const std::string& output, const BuildOptions& options,
                      const MemoryOptions& memory = {});

}  // namespace octiso
