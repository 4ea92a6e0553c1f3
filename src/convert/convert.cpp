// convert() (include/octiso/convert.h): the step loop. 1. open and check every step against the
// first, 2. build and stream the steps one at a time into one OctWriter, 3. measure. Building
// goes through AnyOctree, so no scalar type is named here; sparse-spheres takes its own short
// path because it never has a dense volume.
#include <chrono>
#include <optional>
#include <sys/stat.h>

#include <tbb/global_control.h>

#include "convert/same_grid.h"
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

}  // namespace

ConvertReport convert(const ConvertSource& source, const std::string& output, const BuildOptions& options) {
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

    // 1. Open every step and compare it with the first before anything is written. For raw
    //    input this only maps files; other formats are read once here and once when converted.
    const uint32_t n_steps = source.step_count();
    std::optional<LoadedVolume> step0 = source.load(0);
    const GridOfStep first(*step0);
    if (!source.is_synthetic())
        for (uint32_t i = 1; i < n_steps; ++i) check_same_grid(first, source.load(i));

    OctInfo info;
    info.type = first.type;
    info.dims = first.dims;
    info.placement = first.placement;
    info.dmax = dmax_for(first.dims);
    info.iso_range = options.iso_range;
    info.tolerance = options.tolerance;

    // 2. Build and stream one step at a time; the writer keeps only a temporary file until
    //    finish(), and each step's volume and octree are dropped before the next is opened.
    ConvertReport r;
    BuildOptions opt = options;
    OctWriter writer(output, info);
    for (uint32_t i = 0; i < n_steps; ++i) {
        LoadedVolume v = i == 0 ? std::move(*step0) : source.load(i);
        step0.reset();
        if (i > 0) check_same_grid(first, v);   // a file may have changed since step 1
        opt.source_name = v.source();
        const Clock::time_point t0 = Clock::now();
        const AnyOctree tree = AnyOctree::build(v, opt);
        const double build_seconds = seconds_since(t0);
        ConvertStepReport step{v.source(), tree.info().sizes, build_seconds};
        r.build_seconds += step.build_seconds;
        add_sizes(r.total, step.sizes);
        tree.append_to(writer);
        r.per_step.push_back(std::move(step));
    }
    writer.finish();

    // 3. Measure. The file's size on disk is what a user sees; bytes_written() is the fallback.
    struct stat st {};
    r.file_bytes = ::stat(output.c_str(), &st) == 0 ? uint64_t(st.st_size) : writer.bytes_written();
    r.peak_rss_bytes = peak_rss_bytes();
    r.input = source.name();
    r.output = output;
    r.format = first.format;
    r.type = first.type;
    r.dims = first.dims;
    r.placement = first.placement;
    r.dmax = info.dmax;
    r.steps = n_steps;
    r.iso_range = options.iso_range;
    r.tolerance = options.tolerance;
    r.input_bytes = first.bytes * n_steps;
    r.threads = active_threads();
    r.total_seconds = seconds_since(t_start);
    return r;
}

}  // namespace octiso
