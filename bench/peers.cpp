// octiso-bench peers (issue 5, item 2): octiso against the renderers a user would otherwise pick,
// on the same volume, isovalue and primary rays (PinholeCamera, CONVENTIONS 2): VTK flying edges
// -> Embree triangle BVH, OpenVDB (float grid bytes; level-set tracing of the shifted and scaled
// field), and octiso's lossless octree. Every image is compared with the exact dense reference
// (CONVENTIONS 4) and the targets are printed as measured ratios.
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "bench/bench.h"
#include "bench/peers_mesh.h"
#include "bench/peers_vdb.h"
#include "octiso/build.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/reader.h"
#include "octiso/render.h"
#include "octiso/synthetic.h"
#include "reference/reference_render.h"

namespace octiso::bench {
namespace {

const char* kUsage =
    "usage: octiso-bench peers [--dataset NAME[,NAME...]] [--size N] [--image WxH] [--iso V] [--repeats N]\n"
    "                          [--threads N] [--mri FILE] [--bvh all|robust|fast] [--results DIR]\n"
    "                          [--mesh-normals geometric|vertex] [--quick] [--markdown] [--no-plot]\n"
    "  NAME: plume, mixing (synthetic, N^3, default 256) or mri (default /usr/share/mricron/templates/ch2.nii.gz)\n"
    "  --image: the frame, default 512x512; --quick: 128^3 synthetic, 256x256 frame, 1 repeat\n"
    "  --bvh: the mesh's Embree builds: robust MEDIUM and HIGH, and non-robust HIGH (all, the default),\n"
    "  robust only, or fast (non-robust HIGH) only; each is traced with rtcIntersect8 (8x1, 4x2), rtcIntersect16 (4x4) and rtcIntersect1\n"
    "  --mesh-normals: the mesh shades with the triangle's geometric normal (default: cheaper, and closer to the\n"
    "  exact normal on these data) or with flying edges' interpolated vertex normals";

/// Default isovalues: half-integers, so no voxel of these integer-valued data sets lies exactly on
/// the surface and no method is judged on a tie.
struct OctisoResult {
    double build_seconds = 0;          ///< one-off conversion (not per isovalue)
    uint64_t file_bytes = 0;
    double load_seconds = 0;           ///< OctFile::open + step validation (page cache warm)
    double first_render_seconds = 0;   ///< wall time of a whole render() call
    Frame frame;
    std::function<double()> render;    ///< one more frame; returns its tile-loop seconds
};

template <typename T>
OctisoResult run_octiso(const LoadedVolume& volume, double iso, double warm_iso, const Camera& camera, int threads,
                        const std::string& oct_path) {
    OctisoResult r;
    {
        BuildOptions options;
        options.threads = threads;
        options.source_name = volume.source();
        const auto t0 = std::chrono::steady_clock::now();
        const OctreeData<T> tree = build_octree(volume.view<T>(), options);
        r.build_seconds = seconds_since(t0);
        OctInfo info;
        info.type = volume.type();
        info.dims = volume.dims();
        info.placement = volume.placement();
        info.dmax = tree.dmax;
        OctWriter writer(oct_path, info);
        writer.add_step(tree.view());
        writer.finish();
    }
    r.file_bytes = std::filesystem::file_size(oct_path);

    struct State {
        OctFile file;
        Octree<T> tree;
    };
    auto t0 = std::chrono::steady_clock::now();
    OctFile file = OctFile::open(oct_path);   // Verify::Full: every checksum and index
    const Octree<T> tree = file.step<T>(0);
    r.load_seconds = seconds_since(t0);
    auto state = std::make_shared<State>(State{std::move(file), tree});

    RenderOptions options;
    options.isovalues = {iso};
    options.want_colour = false;   // every method delivers depth + normal, none shades
    options.want_depth = true;
    options.want_normal = true;
    options.threads = threads;
    // "After an isovalue change": one frame at another isovalue first, as in a running viewer.
    RenderOptions warm = options;
    warm.isovalues = {warm_iso};
    (void)render(state->tree, state->file.info().placement, camera, warm);
    t0 = std::chrono::steady_clock::now();
    r.frame = render(state->tree, state->file.info().placement, camera, options);
    r.first_render_seconds = seconds_since(t0);
    r.render = [state, camera, options] { return render(state->tree, state->file.info().placement, camera, options).stats.seconds; };
    return r;
}

std::string percent(double f) { return fmt(100.0 * f, 3) + " %"; }
std::string mb(uint64_t bytes) { return fmt(double(bytes) / 1e6, 2); }
std::string depth_cell(const ImageError& e) { return fmt(e.depth_median, 3) + " / " + fmt(e.depth_p99, 3) + " / " + fmt(e.depth_max, 2); }
std::string normal_cell(const ImageError& e) { return fmt(e.normal_median_deg, 2) + " / " + fmt(e.normal_max_deg, 1); }

void write_error(cli::JsonWriter& j, const ImageError& e) {
    j.key("error").begin_object();
    j.field("mask_mismatch", e.mask_mismatch).field("mask_mismatch_fraction", e.mask_mismatch_fraction).field("both_hit", e.both_hit);
    j.field("depth_median_voxels", e.depth_median).field("depth_p99_voxels", e.depth_p99).field("depth_max_voxels", e.depth_max);
    j.field("normal_median_deg", e.normal_median_deg).field("normal_max_deg", e.normal_max_deg);
    j.end_object();
}

/// One method's numbers, as printed and as written to JSON.
struct Row {
    std::string method;
    double prep_seconds = NAN, bvh_seconds = NAN, render_seconds = NAN, ttfi_seconds = NAN;
    uint64_t bytes = 0;
    std::optional<ImageError> error;
    std::string note;
};

struct Target {
    std::string name;
    double measured = 0, goal = 0;   ///< both as "higher is better" ratios
    std::string how;
};

struct DatasetResult {
    std::string name, source, type;
    Dims dims;
    double iso = 0;
    uint64_t raw_bytes = 0;
    double reference_seconds = 0;
    std::vector<Row> rows;
    std::vector<Target> targets;
    std::vector<std::string> notes;
};

/// An isovalue a quarter of the way from `iso` to the data maximum (or minimum): a different,
/// non-empty surface for the warm-up frames.
double warm_up_iso(const LoadedVolume& volume, double iso) {
    double lo = INFINITY, hi = -INFINITY;
    dispatch_scalar_type(volume.type(), [&](auto tag) {
        using T = decltype(tag);
        const VolumeView<T> view = volume.view<T>();
        for (uint64_t i = 0; i < volume.dims().voxels(); ++i) {
            const double v = double(view.load(i));
            if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
        }
    });
    return hi - iso >= iso - lo ? iso + 0.25 * (hi - iso) : iso - 0.25 * (iso - lo);
}

LoadedVolume open_dataset(const std::string& name, uint32_t n, const std::string& mri_path) {
    if (name == "plume" || name == "mixing") return synthetic_step(name, Dims{n, n, n}, 0);
    if (name == "mri") return open_volume(mri_path, RawOptions{});
    throw Error("--dataset", "expected plume, mixing or mri, found '" + name + "'");
}

/// One mesh configuration the benchmark builds.
struct MeshConfig {
    BvhQuality quality;
    bool robust;
    std::string name() const { return bvh_quality_name(quality) + (robust ? ", robust" : ", not robust"); }
};

DatasetResult run_dataset(const std::string& name, const LoadedVolume& volume, double iso, const Camera& camera, int repeats,
                          int threads, const std::vector<MeshConfig>& configs, bool vertex_normals) {
    DatasetResult d;
    d.name = name;
    d.source = volume.source();
    d.type = std::string(scalar_type_name(volume.type()));
    d.dims = volume.dims();
    d.iso = iso;
    d.raw_bytes = volume.bytes();
    const Placement& placement = volume.placement();
    const double voxel = std::min({placement.spacing[0], placement.spacing[1], placement.spacing[2]});
    std::cerr << "== " << name << " (" << d.source << ", " << d.type << " " << d.dims.x << "x" << d.dims.y << "x" << d.dims.z
              << "), iso " << iso << ", " << camera.width << "x" << camera.height << "\n";

    // The exact answer every method is judged against.
    const auto t0 = std::chrono::steady_clock::now();
    const Frame reference = dispatch_scalar_type(volume.type(), [&](auto tag) {
        using T = decltype(tag);
        return render_reference(volume.view<T>(), placement, camera, std::vector<double>{iso});
    });
    d.reference_seconds = seconds_since(t0);
    std::cerr << "  reference frame " << fmt(d.reference_seconds) << " s\n";

    // Every method renders once at another isovalue before the timed one, so "first image" means
    // the first image after an isovalue change in a warm process, for all of them alike.
    const double warm_iso = warm_up_iso(volume, iso);
    d.notes.push_back("first image = the first frame after a warm-up frame (and for the mesh and OpenVDB the whole "
                      "preprocessing) at isovalue " + fmt(warm_iso, 3));
    d.notes.push_back("render s = median of " + std::to_string(repeats) + " frames per method, interleaved: each round renders "
                      "every method once, the order rotating by one method per round");

    // (c) octiso.
    const std::string oct_path = (std::filesystem::temp_directory_path() /
                                  ("octiso-bench-peers-" + std::to_string(::getpid()) + "-" + name + ".oct")).string();
    OctisoResult oct;
    try {
        oct = dispatch_scalar_type(volume.type(), [&](auto tag) {
            return run_octiso<decltype(tag)>(volume, iso, warm_iso, camera, threads, oct_path);
        });
    } catch (...) {
        std::filesystem::remove(oct_path);
        throw;
    }
    std::filesystem::remove(oct_path);   // the mapping stays valid after the unlink

    // (a) flying edges -> Embree. One untimed pass at the warm-up isovalue first, so that no build
    // pays the process's first Embree device and first large allocations.
    {
        MeshPeerOptions warm;
        warm.quality = configs.front().quality;
        warm.robust = configs.front().robust;
        warm.threads = threads;
        (void)run_mesh_peer(volume, warm_iso, camera, warm);
    }
    std::vector<MeshPeerResult> meshes;
    for (const MeshConfig& c : configs) {
        MeshPeerOptions options;
        options.quality = c.quality;
        options.robust = c.robust;
        options.vertex_normals = vertex_normals;
        options.threads = threads;
        meshes.push_back(run_mesh_peer(volume, iso, camera, options));
        std::cerr << "  mesh (" << c.name() << "): " << meshes.back().triangles << " triangles, extract "
                  << fmt(meshes.back().extract_seconds) << " s, BVH " << fmt(meshes.back().bvh_seconds) << " s\n";
    }

    // (b) OpenVDB.
    (void)run_vdb_peer(volume, warm_iso, camera);   // warm-up, as above
    VdbPeerResult vdb = run_vdb_peer(volume, iso, camera);

    // The timed repeats, interleaved: every round renders each method once, so a burst of load from
    // another process on this shared machine lands on all methods alike, not on one.
    std::vector<std::pair<std::string, std::function<double()>>> methods;
    methods.emplace_back("octiso", oct.render);
    for (size_t m = 0; m < meshes.size(); ++m)
        for (MeshRays rays : {MeshRays::packet8, MeshRays::packet8_block, MeshRays::packet16_block, MeshRays::single})
            methods.emplace_back("mesh " + std::to_string(m) + " " + mesh_rays_name(rays),
                                 [&meshes, m, rays] { return meshes[m].render(rays, nullptr); });
    if (vdb.ran) methods.emplace_back("openvdb", [&vdb] { return vdb.render(nullptr); });
    std::vector<std::vector<double>> seconds(methods.size());
    for (int k = 0; k < std::max(repeats, 1); ++k)
        for (size_t i = 0; i < methods.size(); ++i) {
            const size_t j = (i + size_t(k)) % methods.size();
            seconds[j].push_back(methods[j].second());
        }
    auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
    };
    size_t next = 0;
    const double oct_render = median(seconds[next++]);
    std::cerr << "  octiso: render " << fmt(oct_render) << " s\n";
    {
        Row row;
        row.method = "octiso (lossless .oct)";
        row.prep_seconds = oct.load_seconds;
        row.render_seconds = oct_render;
        row.ttfi_seconds = oct.first_render_seconds;
        row.bytes = oct.file_bytes;
        row.error = compare_frames(oct.frame, reference, voxel);
        row.note = "prep = load + validate; octree build (once per volume) " + fmt(oct.build_seconds) + " s; render() with "
                   "its default path: the packet kernel called directly with 16-ray packets of 4x4 pixels";
        d.rows.push_back(row);
    }
    double best_mesh_render = INFINITY, best_mesh_ttfi = INFINITY;
    uint64_t least_mesh_bytes = UINT64_MAX;
    std::string best_mesh_name;
    for (size_t m = 0; m < meshes.size(); ++m) {
        const MeshPeerResult& mr = meshes[m];
        const ImageError error = compare_frames(mr.frame, reference, voxel);
        const ImageError geometric = compare_frames(mr.frame_geometric, reference, voxel);
        for (MeshRays rays : {MeshRays::packet8, MeshRays::packet8_block, MeshRays::packet16_block, MeshRays::single}) {
            const double render_s = median(seconds[next++]);
            Row row;
            row.method = "FE + Embree (" + configs[m].name() + ", " + mesh_rays_name(rays) + ")";
            row.prep_seconds = mr.extract_seconds;
            row.bvh_seconds = mr.bvh_seconds;
            row.render_seconds = render_s;
            // The first frame is always traced with packets, so both rows share it.
            row.ttfi_seconds = mr.time_to_first_image();
            row.bytes = mr.mesh_bytes + mr.bvh_bytes;
            row.error = error;
            row.note = std::to_string(mr.triangles) + " triangles, mesh " + mb(mr.mesh_bytes) + " MB + BVH " + mb(mr.bvh_bytes) +
                       " MB; " + (vertex_normals ? "interpolated vertex normals (geometric normal error: " + normal_cell(geometric) + " deg)"
                                                 : std::string("geometric normals"));
            d.rows.push_back(row);
            if (render_s < best_mesh_render) best_mesh_render = render_s, best_mesh_name = row.method;
        }
        best_mesh_ttfi = std::min(best_mesh_ttfi, mr.time_to_first_image());
        least_mesh_bytes = std::min(least_mesh_bytes, mr.mesh_bytes + mr.bvh_bytes);
        std::cerr << "  mesh (" << configs[m].name() << "): render " << fmt(d.rows[d.rows.size() - 2].render_seconds) << " s (8), "
                  << fmt(d.rows.back().render_seconds) << " s (1)\n";
    }
    double vdb_render = NAN;
    if (vdb.ran) {
        vdb_render = median(seconds[next++]);
        std::cerr << "  openvdb: level set " << fmt(vdb.levelset_seconds) << " s, render " << fmt(vdb_render) << " s\n";
        Row dense;
        dense.method = "OpenVDB float grid (bytes only)";
        dense.prep_seconds = vdb.dense_seconds;
        dense.bytes = vdb.dense_bytes;
        dense.note = "copyFromDense tolerance 0, background = data minimum; " + std::to_string(vdb.dense_leaves) + " leaves, " +
                     std::to_string(vdb.dense_active_voxels) + " active voxels";
        d.rows.push_back(dense);
        Row ls;
        ls.method = "OpenVDB level set";
        ls.prep_seconds = vdb.to_float_seconds + vdb.levelset_seconds;
        ls.render_seconds = vdb_render;
        ls.ttfi_seconds = vdb.time_to_first_image();
        ls.bytes = vdb.levelset_bytes;
        ls.error = compare_frames(vdb.frame, reference, voxel);
        ls.note = "g = s*(iso - f), s = " + fmt(vdb.scale, 5) + ", background " + fmt(vdb.background, 4) +
                  "; prep = to float + max cell range + shift/scale + copyFromDense";
        d.rows.push_back(ls);
    } else {
        d.notes.push_back("OpenVDB rows skipped: " + vdb.skipped);
    }
    {
        Row raw;
        raw.method = "raw array (for scale)";
        raw.bytes = volume.bytes();
        d.rows.push_back(raw);
    }

    // The targets, each as a ratio where higher is better, against the peer's best row.
    if (!meshes.empty()) {
        d.targets.push_back({"octree render speed / Embree mesh render speed", best_mesh_render / oct_render, 0.5,
                             "fastest Embree row (" + best_mesh_name + ") / octiso render"});
        d.targets.push_back({"time to first image after an isovalue change, mesh / octree", best_mesh_ttfi / oct.first_render_seconds,
                             10.0, "(extract + BVH + first render, fastest configuration) / octiso's first render"});
        d.targets.push_back({"(mesh + BVH bytes) / octree bytes", double(least_mesh_bytes) / double(oct.file_bytes), 3.0,
                             "smallest mesh + BVH / .oct file bytes"});
    }
    if (vdb.ran)
        d.targets.push_back({"OpenVDB level-set render time / octree render time", vdb_render / oct_render, 3.0,
                             "LevelSetRayIntersector render / octiso render"});
    return d;
}

void print_dataset(const DatasetResult& d, bool markdown) {
    auto s = [](double v) { return std::isnan(v) ? std::string("-") : fmt(v, 3); };
    Table t({"method", "prep s", "BVH s", "render s", "Mrays/s", "first image s", "MB", "mask mismatch",
             "depth med/p99/max (vox)", "normal med/max (deg)"});
    for (const Row& r : d.rows) {
        const std::string mrays = std::isnan(r.render_seconds) ? "-" : fmt(double(r.error ? r.error->pixels : 0) / r.render_seconds * 1e-6, 2);
        t.add({r.method, s(r.prep_seconds), s(r.bvh_seconds), s(r.render_seconds), mrays, s(r.ttfi_seconds), mb(r.bytes),
               r.error ? percent(r.error->mask_mismatch_fraction) : "-", r.error ? depth_cell(*r.error) : "-",
               r.error ? normal_cell(*r.error) : "-"});
    }
    std::cout << "\n### " << d.name << ": " << d.source << " (" << d.type << ", " << d.dims.x << "x" << d.dims.y << "x" << d.dims.z
              << "), iso " << d.iso << "\n\n";
    if (markdown) t.print_markdown(std::cout);
    else t.print(std::cout);
    std::cout << "\n";
    for (const Row& r : d.rows)
        if (!r.note.empty()) std::cout << "- " << r.method << ": " << r.note << "\n";
    for (const auto& n : d.notes) std::cout << "- " << n << "\n";
    std::cout << "- reference (exact dense tracer) frame: " << fmt(d.reference_seconds) << " s\n\n";
    Table targets({"target", "measured", "goal", "met?"});
    for (const Target& g : d.targets)
        targets.add({g.name, fmt(g.measured, 2) + "x", ">= " + fmt(g.goal, 1) + "x", g.measured >= g.goal ? "yes" : "NO"});
    if (markdown) targets.print_markdown(std::cout);
    else targets.print(std::cout);
}

/// The 1-minute load average: the machine is shared, and the report should say how busy it was.
std::string load_average() {
    std::ifstream in("/proc/loadavg");
    std::string one;
    in >> one;
    return one;
}

int run_peers(cli::Args& args) {
    if (args.flag("--help") || args.flag("-h")) {
        std::cout << kUsage << "\n";
        return 0;
    }
    const bool quick = args.flag("--quick");
    const std::string datasets_text = args.value("--dataset").value_or("plume,mixing,mri");
    const uint32_t n = uint32_t(cli::parse_int(args.value("--size").value_or(quick ? "128" : "256"), "--size", 2, 4096));
    const auto image = cli::parse_size(args.value("--image").value_or(quick ? "256x256" : "512x512"), "--image");
    const auto iso_text = args.value("--iso");
    const int repeats = int(cli::parse_int(args.value("--repeats").value_or(quick ? "1" : "3"), "--repeats", 1, 1000));
    const int threads = int(cli::parse_int(args.value("--threads").value_or("0"), "--threads", 0, 4096));
    const std::string mri = args.value("--mri").value_or("/usr/share/mricron/templates/ch2.nii.gz");
    const std::string bvh = args.value("--bvh").value_or("all");
    const std::string normals = args.value("--mesh-normals").value_or("geometric");
    const bool markdown = args.flag("--markdown"), no_plot = args.flag("--no-plot");
    const std::string dir = results_dir(args);
    args.finish();

    std::vector<MeshConfig> configs;
    if (bvh == "all" || bvh == "robust") configs.push_back({BvhQuality::medium, true}), configs.push_back({BvhQuality::high, true});
    if (bvh == "all" || bvh == "fast") configs.push_back({BvhQuality::high, false});
    if (configs.empty()) throw Error("--bvh", "expected all, robust or fast, found '" + bvh + "'");
    if (normals != "vertex" && normals != "geometric")
        throw Error("--mesh-normals", "expected vertex or geometric, found '" + normals + "'");
    std::vector<std::string> names;
    {
        std::stringstream ss(datasets_text);
        for (std::string item; std::getline(ss, item, ',');)
            if (!item.empty()) names.push_back(item);
    }
    std::optional<tbb::global_control> limit;
    if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, size_t(threads));

    std::cout << "octiso-bench peers on " << machine_description() << " (load average " << load_average() << ")\n";
    std::vector<DatasetResult> results;
    for (const std::string& name : names) {
        LoadedVolume volume = open_dataset(name, n, mri);
        const double iso = iso_text ? cli::parse_double(*iso_text, "--iso") : default_isovalue(name);
        const Camera camera = frame_data_box(volume.dims(), volume.placement(), image[0], image[1]);
        results.push_back(run_dataset(name, volume, iso, camera, repeats, threads, configs, normals == "vertex"));
        print_dataset(results.back(), markdown);
    }

    const std::string json = write_json(dir, "peers", [&](cli::JsonWriter& j) {
        j.begin_object().field("machine", machine_description()).field("load_average", load_average()).field("width", image[0]).field("height", image[1]);
        j.field("synthetic_size", n).field("repeats", repeats).field("threads", threads).field("mesh_normals", normals);
        j.field("openvdb", vdb_available());
        j.key("datasets").begin_array();
        for (const DatasetResult& d : results) {
            j.begin_object().field("name", d.name).field("source", d.source).field("type", d.type);
            j.key("dims").array(std::vector<uint32_t>{d.dims.x, d.dims.y, d.dims.z});
            j.field("iso", d.iso).field("raw_bytes", d.raw_bytes).field("reference_seconds", d.reference_seconds);
            j.key("methods").begin_array();
            for (const Row& r : d.rows) {
                j.begin_object().field("method", r.method).field("prep_seconds", r.prep_seconds).field("bvh_seconds", r.bvh_seconds);
                j.field("render_seconds", r.render_seconds).field("first_image_seconds", r.ttfi_seconds).field("bytes", r.bytes);
                if (r.error) write_error(j, *r.error);
                j.field("note", r.note).end_object();
            }
            j.end_array();
            j.key("targets").begin_array();
            for (const Target& g : d.targets)
                j.begin_object().field("name", g.name).field("measured", g.measured).field("goal", g.goal).field("how", g.how).end_object();
            j.end_array();
            j.key("notes").array(d.notes);
            j.end_object();
        }
        j.end_array().end_object();
    });
    std::cerr << "results: " << json << "\n";
    if (!no_plot) plot("peers", json, dir + "/peers.png");
    return 0;
}

}  // namespace

static const bool kRegistered =
    register_bench("peers", "octiso vs flying edges + Embree BVH and OpenVDB level sets: time, bytes, image error", &run_peers);

}  // namespace octiso::bench
