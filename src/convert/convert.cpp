// convert() (include/octiso/convert.h): the step loop. 1. open and check every step against the
// first, 2. build and stream the steps one at a time into one OctWriter, 3. measure. Building
// goes through AnyOctree, so no scalar type is named here; sparse-spheres takes its own short
// path because it never has a dense volume.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <tbb/global_control.h>

#include "convert/same_grid.h"
#include "convert/stream_build.h"
#include "io/header_check.h"
#include "io/nifti_header.h"
#include "io/text_layout.h"
#include "io/volume_stream.h"
#include "octiso/any_octree.h"
#include "octiso/convert.h"
#include "octiso/output_guard.h"
#include "octree/sparse_synthetic.h"
#include "util/process_memory.h"

namespace octiso {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void add_sizes(StepSizes& total, const StepSizes& s) {
    if (total.nodes_per_depth.size() < s.nodes_per_depth.size()) total.nodes_per_depth.resize(s.nodes_per_depth.size());
    if (total.scalar_leaves_per_depth.size() < s.scalar_leaves_per_depth.size())
        total.scalar_leaves_per_depth.resize(s.scalar_leaves_per_depth.size());
    for (size_t d = 0; d < s.nodes_per_depth.size(); ++d) total.nodes_per_depth[d] += s.nodes_per_depth[d];
    for (size_t d = 0; d < s.scalar_leaves_per_depth.size(); ++d) total.scalar_leaves_per_depth[d] += s.scalar_leaves_per_depth[d];
    total.interior_bytes += s.interior_bytes;
    total.minmax_bytes += s.minmax_bytes;
    total.cap_bytes += s.cap_bytes;
}

int active_threads() { return int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)); }

/// sparse-spheres:N: the analytic field straight into an octree, one step, default placement.
ConvertReport convert_sparse_spheres(const ConvertSource& source, const std::string& output, Clock::time_point t0) {
    const SparseSpheres field = sparse_spheres_layout(source.sparse_spheres_n());
    const AnyOctree tree = AnyOctree::adopt(build_sparse_octree<float>(field), Placement{});
    OctWriter writer(output, tree.oct_info());
    tree.append_to(writer);
    writer.finish();

    ConvertReport r;
    r.input = source.name();
    r.output = output;
    r.format = VolumeFormat::synthetic;
    r.type = tree.type();
    r.dims = tree.dims();
    r.dmax = tree.dmax();
    r.steps = 1;
    r.built_directly = true;
    r.total = tree.info().sizes;
    r.per_step.push_back({source.name(), r.total, 0.0});
    r.file_bytes = writer.bytes_written();
    r.total_seconds = seconds_since(t0);
    r.threads = active_threads();
    return r;
}

/// What both build paths report alike once the file is written: sizes, names, grid, options.
/// The file's size on disk is what a user sees; bytes_written() is the fallback.
void fill_report(ConvertReport& r, const ConvertSource& source, const std::string& output,
                 const convert_detail::GridOfStep& first, int dmax, uint32_t n_steps, const BuildOptions& options,
                 const OctWriter& writer) {
    struct stat st {};
    r.file_bytes = ::stat(output.c_str(), &st) == 0 ? uint64_t(st.st_size) : writer.bytes_written();
    r.peak_rss_bytes = peak_rss_bytes();
    r.input = source.name();
    r.output = output;
    r.format = first.format;
    r.type = first.type;
    r.dims = first.dims;
    r.placement = first.placement;
    r.dmax = dmax;
    r.steps = n_steps;
    r.iso_range = options.iso_range;
    r.tolerance = options.tolerance;
    r.value_scale = first.value_scale;
    r.flipped_axes = first.flipped_axes;
    if (!first.warning.empty()) r.warnings.push_back(first.warning);
}

/// The build's options in stored values: --iso-range, --tolerance and --nan-as are given in
/// real values (CONVENTIONS 2b), the tree and its builder see stored ones.
BuildOptions stored_options(const BuildOptions& real, const convert_detail::GridOfStep& first) {
    const ValueScale& s = first.value_scale;
    BuildOptions o = real;
    o.value_scale = s;
    o.flipped_axes = first.flipped_axes;
    if (s.is_identity()) return o;
    if (real.iso_range) o.iso_range = s.stored_range(*real.iso_range);
    o.tolerance = real.tolerance / std::fabs(s.slope);
    if (real.nan_as) o.nan_as = s.stored(*real.nan_as);
    if ((o.iso_range && !(std::isfinite((*o.iso_range)[0]) && std::isfinite((*o.iso_range)[1]) && (*o.iso_range)[0] < (*o.iso_range)[1])) ||
        !std::isfinite(o.tolerance))
        throw Error(first.source, "--iso-range/--tolerance in real values do not map to a finite stored range (LO < HI) through scl_slope " +
                                      std::to_string(s.slope));
    return o;
}

/// The header of the file: grid and source order of step 0, the options in stored values.
OctInfo oct_info_of(const convert_detail::GridOfStep& first, const BuildOptions& stored) {
    OctInfo info;
    info.type = first.type;
    info.dims = first.dims;
    info.placement = first.placement;
    info.dmax = dmax_for(first.dims);
    info.iso_range = stored.iso_range;
    info.tolerance = stored.tolerance;
    info.value_scale = first.value_scale;
    info.flipped_axes = first.flipped_axes;
    return info;
}

convert_detail::GridOfStep grid_of(const VolumeStream& s) {
    return {s.source(), s.format(), s.type(), s.dims(), s.placement(), s.bytes(), s.value_scale(), s.flipped_axes(), s.warning()};
}

/// Out of core (stream_build.h): every step opened as a stream and checked against the first,
/// the plan checked against the budget, then the steps built and streamed one at a time.
ConvertReport convert_streamed(const ConvertSource& source, const std::string& output, const BuildOptions& options,
                               const MemoryOptions& memory, uint64_t budget, Clock::time_point t_start) {
    using convert_detail::GridOfStep;
    const uint32_t n_files = source.step_count();
    std::unique_ptr<VolumeStream> step0 = open_volume_stream(source.step_path(0), source.raw_options());
    const GridOfStep first = grid_of(*step0);
    for (uint32_t i = 1; i < n_files; ++i) {
        const std::unique_ptr<VolumeStream> s = open_volume_stream(source.step_path(i), source.raw_options());
        convert_detail::check_same_grid(first, grid_of(*s));
        if (s->time_steps() != 1) throw Error(s->source(), "a 4-D file is a series by itself; list only 3-D files");
    }
    // A 4-D NIfTI is a time series in one file: its volumes are the steps, read from one stream.
    const uint32_t per_file = step0->time_steps();
    if (per_file != 1 && n_files != 1) throw Error(step0->source(), "a 4-D file is a series by itself; list only 3-D files");
    const uint32_t n_steps = n_files * per_file;
    const convert_detail::StreamPlan plan = convert_detail::plan_stream(first.dims, first.type, options, budget, memory.piece_side, first.source);

    BuildOptions opt = stored_options(options, first);
    const OctInfo info = oct_info_of(first, opt);

    ConvertReport r;
    OctWriter writer(output, info);
    const uint64_t all_bytes = first.bytes * n_steps;
    const uint64_t layer_voxels = uint64_t(first.dims.x) * first.dims.y;
    for (uint32_t i = 0; i < n_steps; ++i) {
        std::unique_ptr<VolumeStream> opened;
        if (per_file == 1) opened = i == 0 ? std::move(step0) : open_volume_stream(source.step_path(i), source.raw_options());
        else if (i > 0) step0->start_next_step();
        VolumeStream* s = per_file == 1 ? opened.get() : step0.get();
        if (i > 0 && per_file == 1) convert_detail::check_same_grid(first, grid_of(*s));   // a file may have changed since
        opt.source_name = s->source();
        const uint64_t done_before = first.bytes * i;
        std::function<void(uint32_t)> on_layers;
        if (memory.on_progress)
            on_layers = [&](uint32_t layers) {
                memory.on_progress(done_before + layers * s->layer_bytes(), all_bytes,
                                   (uint64_t(i) * first.dims.z + layers) * layer_voxels);
            };
        const convert_detail::StreamStepResult res =
            convert_detail::stream_build_step(*s, opt, plan, writer, output, on_layers);
        r.build_seconds += res.build_seconds;
        r.slabs_seconds += res.slabs_seconds, r.top_seconds += res.top_seconds, r.sections_seconds += res.sections_seconds;
        r.spilled_bytes += res.spilled_bytes;
        if (per_file == 1 || i + 1 == n_steps) r.bytes_read += s->file_bytes_read();
        add_sizes(r.total, res.sizes);
        r.per_step.push_back({s->source(), res.sizes, res.build_seconds});
    }
    writer.finish();

    fill_report(r, source, output, first, info.dmax, n_steps, options, writer);
    r.input_bytes = all_bytes;
    r.threads = active_threads();
    r.streamed = true;
    r.memory_budget = budget;
    r.piece_side = plan.piece_side;
    r.total_seconds = seconds_since(t_start);
    return r;
}

}  // namespace

uint64_t default_memory_budget() {
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
    uint64_t budget = pages > 0 && page > 0 ? uint64_t(pages) / 4 * uint64_t(page) : uint64_t(1) << 30;
    // Under ulimit -v the address space is the tighter limit: keep half of it for everything else.
    struct rlimit as {};
    if (::getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) budget = std::min<uint64_t>(budget, as.rlim_cur / 2);
    return budget;
}

ConvertReport convert(const ConvertSource& source, const std::string& output, const BuildOptions& options,
                      const MemoryOptions& memory) {
    using convert_detail::check_same_grid;
    using convert_detail::GridOfStep;
    const Clock::time_point t_start = Clock::now();
    if (source.is_sparse_spheres()) return convert_sparse_spheres(source, output, t_start);
    if (!source.is_synthetic()) {   // never replace an input (issue 18: same device and inode)
        std::vector<std::string> inputs;
        for (uint32_t i = 0; i < source.step_count(); ++i) inputs.push_back(source.step_path(i));
        refuse_output_onto_input(output, inputs);
    }
    std::optional<tbb::global_control> limit;   // reading, generating and building alike
    if (options.threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, size_t(options.threads));

    // 0. In memory or out of core. The in-memory build holds the input and the whole octree, about
    //    twice the input (BENCHMARKS.md, compression: 1.1x of input + output).
    const uint64_t budget = memory.budget.value_or(default_memory_budget());
    if (memory.budget && *memory.budget == 0) throw Error("--memory", "must be > 0");
    if (memory.force_in_memory && (memory.budget || memory.force_streaming))
        throw Error("--in-memory", "does not combine with --memory");
    const bool streamable =
        !memory.force_in_memory && !source.is_synthetic() && is_streamable(source.step_path(0), source.raw_options());
    if (streamable) {
        // Bad dims are reported by either reader with the same words; let the in-memory one do it.
        const VolumeFormat format =
            source.raw_options().dims ? VolumeFormat::raw : detect_volume_format(source.step_path(0));
        const bool nifti = format == VolumeFormat::nifti;
        std::optional<io::NiftiHeader> header;
        if (nifti) header = io::read_nifti_header(source.step_path(0));
        std::optional<io::DataLayout> layout;
        if (format == VolumeFormat::nrrd || format == VolumeFormat::meta_image)
            layout = io::text_data_layout(source.step_path(0), format).layout;   // streamable: it has one
        const Dims d = nifti ? header->dims : layout ? layout->dims : *source.raw_options().dims;
        const ScalarType t = nifti ? header->type : layout ? layout->type : *source.raw_options().type;
        const bool valid = d.x && d.y && d.z && d.max_extent() <= Dims::kMaxExtent &&
                           d.voxels() / d.x / d.y == d.z && d.voxels() <= UINT64_MAX / 8;
        const bool fits = !valid || d.voxels() * scalar_type_bytes(t) <= budget / 2;
        // VTK reads a 4-D NIfTI as components, which octiso refuses: only the stream reads its steps.
        const bool four_d = nifti && header->time_steps > 1;
        if (memory.budget || memory.force_streaming || !fits || four_d)
            return convert_streamed(source, output, options, memory, budget, t_start);
    }

    // 1. Open every step and compare it with the first before anything is written. For raw
    //    input this only maps files; other formats are read once here and once when converted.
    const uint32_t n_steps = source.step_count();
    // Input VTK must read whole is refused over an explicit budget before VTK allocates it, from
    // the header's declaration (header_check.h), and again after reading if the header said nothing.
    auto too_big_for_budget = [&](const std::string& path, VolumeFormat format, uint64_t bytes) {
        return Error(path, std::string(volume_format_name(format)) + " input is read whole (through VTK): its " +
                               std::to_string(bytes) + " voxel bytes exceed --memory " + std::to_string(*memory.budget) +
                               " (convert it to raw to stream it)");
    };
    if (memory.budget && !source.is_synthetic() && !source.raw_options().dims && !source.raw_options().type) {
        const VolumeFormat f = detect_volume_format(source.step_path(0));
        if (f != VolumeFormat::raw && f != VolumeFormat::nifti) {
            const uint64_t declared = io::check_declared_size(source.step_path(0), f);
            if (declared > *memory.budget) throw too_big_for_budget(source.step_path(0), f, declared);
        }
    }
    std::optional<LoadedVolume> step0 = source.load(0);
    const GridOfStep first(*step0);
    if (memory.budget && !source.is_synthetic() && first.bytes > *memory.budget)
        throw too_big_for_budget(first.source, first.format, first.bytes);
    if (!source.is_synthetic())
        for (uint32_t i = 1; i < n_steps; ++i) check_same_grid(first, source.load(i));

    BuildOptions opt = stored_options(options, first);
    const OctInfo info = oct_info_of(first, opt);

    // 2. Build and stream one step at a time; the writer keeps only a temporary file until
    //    finish(), and each step's volume and octree are dropped before the next is opened.
    ConvertReport r;
    OctWriter writer(output, info);
    r.read_seconds = seconds_since(t_start);   // step 0 (and the others' checks) read above
    for (uint32_t i = 0; i < n_steps; ++i) {
        const Clock::time_point t_read = Clock::now();
        LoadedVolume v = i == 0 ? std::move(*step0) : source.load(i);
        if (i > 0) r.read_seconds += seconds_since(t_read);
        step0.reset();
        if (i > 0) check_same_grid(first, v);   // a file may have changed since step 1
        opt.source_name = v.source();
        const Clock::time_point t0 = Clock::now();
        const AnyOctree tree = AnyOctree::build(v, opt);
        const double build_seconds = seconds_since(t0);
        const AnyOctreeInfo built = tree.info();
        ConvertStepReport step{v.source(), built.sizes, build_seconds};
        r.build_seconds += step.build_seconds;
        if (const auto& p = built.build_phases) {
            r.build_phases.prepare += p->prepare, r.build_phases.pieces += p->pieces, r.build_phases.top += p->top;
            r.build_phases.concatenate += p->concatenate, r.build_phases.release += p->release;
            r.build_phases.pieces_busy += p->pieces_busy;
        }
        add_sizes(r.total, step.sizes);
        const Clock::time_point t_write = Clock::now();
        tree.append_to(writer);
        r.write_seconds += seconds_since(t_write);
        r.per_step.push_back(std::move(step));
        if (memory.on_progress) memory.on_progress(first.bytes * (i + 1), first.bytes * n_steps, first.dims.voxels() * (i + 1));
    }
    const Clock::time_point t_finish = Clock::now();
    writer.finish();
    r.write_seconds += seconds_since(t_finish);

    // 3. Measure.
    fill_report(r, source, output, first, info.dmax, n_steps, options, writer);
    r.input_bytes = first.bytes * n_steps;
    r.threads = active_threads();
    r.memory_budget = budget;
    r.total_seconds = seconds_since(t_start);
    return r;
}

}  // namespace octiso
