// octiso-bench lod (issue 14): what level of detail (RenderOptions::lod, src/render/lod.h) buys in
// frame time and file bytes touched, and what it costs in image error, against the exact
// full-resolution frame of the same octree. For each dataset, image size and view, interleaved in
// one run (each round renders every factor once, the first one rotating):
//   frame time       minimum over the rounds (1 thread: the thread's CPU time) and exact / LOD;
//   mask mismatch    pixels hit in one frame and not the other, over the exact frame's hits;
//   depth error      |t_lod - t_exact| in voxels of the finest axis, over pixels hit in both:
//                    median, p99, max; normal error in degrees (median, p99);
//   bytes touched    the file's pages resident in this process after one frame, from none
//                    (OctFile::release_resident_pages, then /proc/self/smaps Rss of the mapping);
//   stopping depths  the share of hits per octree depth (dmax: full resolution);
//   identical        depth and normals bit for bit the exact frame's;
//   cold (--cold N)  the whole view only: the first frame of a process that opens the file
//                    after it was dropped from the page cache, as `octiso-render FILE --lod F
//                    --json` (its default verify and camera, the whole view's) reports it: the
//                    frame's wall time (its page faults' reads and, under --verify touched, the
//                    checks of the blocks it reaches count), the minimum over N interleaved
//                    rounds, and the exact one over it. Its open_to_first_frame_seconds also
//                    holds loading the image library (OpenImageIO, about 0.4 s here) before the
//                    frame, the same for every factor: in the JSON, not in the ratio.
// Views: "whole" is frame_data_box; "close" keeps its eye and looks through a field of view 8x
// narrower, so the pixel footprint is 8x smaller (the table prints it, in voxels at the centre);
// "near" (not in the default set) moves the eye halfway to the centre, so that the distance, and
// with it the cut, varies across the surface: where levels meet, "holes" counts the cracks.
// --rules compares the representative value of a coarse level (deliverable 1): the dense array
// reduced by each rule to lattice unit u, placed with spacing u, traced exactly, against the
// exact frame (whole view, first image size; the array cropped to 8k+1 voxels per axis, its
// exact frame the reference): decimation (format 4's lattice sample, what --lod
// traces where the cut is uniform), a box mean and a range midpoint over the u+1 voxels per axis
// centred on each lattice point (half weight at the ends: the box of width u).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include <tbb/parallel_for.h>

#include "bench/bench.h"
#include "bench/dataset_spec.h"
#include "bench/tools.h"
#include "octiso/any_octree.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/reader.h"
#include "octiso/render.h"
#include "octiso/synthetic.h"

namespace octiso::bench {
namespace {

const char* const kLodUsage =
    "usage: octiso-bench lod [--dataset SPEC[,SPEC...]] [--lod 0.5,1,2,4] [--image 512,1024] [--view whole,close[,near]]\n"
    "                        [--threads N] [--repeats N] [--cold N] [--rules] [--mri-dir DIR] [--work DIR] [--quick]\n"
    "                        [--markdown] [--results DIR] [--tag T] [--no-plot]\n"
    "  SPEC: FILE.oct@ISO (used as it is), FILE@ISO (a scan in --mri-dir, default /usr/share/mricron/templates)\n"
    "        or NAME:N@ISO (plume, mixing at N^3); scans and synthetics are converted with octiso-convert into\n"
    "        --work (default a temporary folder, removed at the end)\n"
    "  default: plume:1024@40.5, mixing:1024@127.5, ch2better.nii.gz@100.5, ch2better.nii.gz@25.5; 1 thread, 3 rounds\n"
    "  --cold N: also N rounds of a first frame from a cold page cache (whole view, octiso-render)\n"
    "  --quick: plume:64@40.5, 128x128, factors 1,4, 1 round, --rules at units 2; --tag T: write lod_T.json";

struct FrameError {
    uint64_t exact_hits = 0, mismatched = 0;
    /// Cracks: pixels the exact frame hits and this one misses while this one hits both
    /// neighbours on a row or on a column (a gap inside a surface, not a shifted silhouette).
    uint64_t holes = 0;
    double mismatch = 0;   ///< mismatched / exact_hits
    double depth_median = 0, depth_p99 = 0, depth_max = 0;   ///< voxels
    double normal_median = 0, normal_p99 = 0;                ///< degrees
    bool identical = false;
};

double quantile(std::vector<double>& v, double q) {
    if (v.empty()) return 0;
    const size_t k = std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5));
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
    return v[k];
}

FrameError compare(const Frame& f, const Frame& exact, double voxel) {
    FrameError e;
    std::vector<double> depth, normal;
    for (size_t i = 0; i < exact.depth.size(); ++i) {
        const bool a = std::isfinite(f.depth[i]), b = std::isfinite(exact.depth[i]);
        e.exact_hits += b;
        if (a != b) {
            ++e.mismatched;
            const size_t w = size_t(f.width), x = i % w, y = i / w;
            auto hit = [&](size_t j) { return std::isfinite(f.depth[j]); };
            if (b && x > 0 && x + 1 < w && y > 0 && y + 1 < size_t(f.height) &&
                ((hit(i - 1) && hit(i + 1)) || (hit(i - w) && hit(i + w))))
                ++e.holes;
            continue;
        }
        if (!a) continue;
        depth.push_back(std::fabs(double(f.depth[i]) - double(exact.depth[i])) / voxel);
        double dot = 0;
        for (int k = 0; k < 3; ++k) dot += double(f.normal[3 * i + k]) * double(exact.normal[3 * i + k]);
        normal.push_back(std::acos(std::clamp(dot, -1.0, 1.0)) * 180 / M_PI);
    }
    e.mismatch = e.exact_hits ? double(e.mismatched) / double(e.exact_hits) : 0;
    e.depth_max = depth.empty() ? 0 : *std::max_element(depth.begin(), depth.end());
    e.depth_median = quantile(depth, 0.5), e.depth_p99 = quantile(depth, 0.99);
    e.normal_median = quantile(normal, 0.5), e.normal_p99 = quantile(normal, 0.99);
    e.identical = f.depth.size() == exact.depth.size() &&
                  std::memcmp(f.depth.data(), exact.depth.data(), f.depth.size() * sizeof(float)) == 0 &&
                  std::memcmp(f.normal.data(), exact.normal.data(), f.normal.size() * sizeof(float)) == 0;
    return e;
}

struct CaseRow {
    std::string dataset, view;
    double iso = 0, footprint = 0, lod = 0, seconds = 0, speedup = 1;
    int image = 0;
    uint64_t touched = 0, file_bytes = 0;
    /// --cold: the first frame from a cold page cache (wall seconds, minimum), the exact one
    /// over it, that run's open to first frame, and the file's bytes resident after that frame;
    /// 0 where not measured.
    double cold_seconds = 0, cold_speedup = 0, cold_open_to_frame = 0;
    uint64_t cold_resident = 0;
    FrameError error;
    std::map<int, uint64_t> hit_depths;   ///< depth -> hits
};

struct RuleRow {
    std::string dataset, rule;
    double iso = 0;
    uint32_t unit = 0;
    FrameError error;
};

/// The dense array reduced to lattice unit u by `rule` (0 decimate, 1 box mean, 2 range
/// midpoint), as floats: output voxel q is the rule over the input voxels within u/2 of u q on
/// every axis (clamped at the borders; the mean weighs each axis' two end taps by 1/2, a box of
/// width u). Direct per output voxel, (u+1)^3 reads each: no full-size temporary.
template <typename T> std::vector<float> reduce(const VolumeView<T>& v, uint32_t u, int rule, Dims& out_dims) {
    const Dims in = v.dims;
    out_dims = Dims{(in.x - 1) / u + 1, (in.y - 1) / u + 1, (in.z - 1) / u + 1};
    const Dims n = out_dims;
    std::vector<float> out(n.voxels());
    const int64_t half = int64_t(u / 2);
    auto taps = [&](int64_t centre, uint32_t extent, int64_t& lo, int64_t& hi) {
        lo = std::max<int64_t>(0, centre - half), hi = std::min<int64_t>(int64_t(extent) - 1, centre + half);
    };
    auto weight = [&](int64_t k, int64_t centre) { return k == centre - half || k == centre + half ? 0.5 : 1.0; };
    tbb::parallel_for(uint32_t(0), n.z, [&](uint32_t z) {
        for (uint32_t y = 0; y < n.y; ++y)
            for (uint32_t x = 0; x < n.x; ++x) {
                const int64_t c[3] = {int64_t(x) * u, int64_t(y) * u, int64_t(z) * u};
                float& o = out[x + uint64_t(n.x) * (y + uint64_t(n.y) * z)];
                if (rule == 0) {
                    o = float(v.at(uint32_t(c[0]), uint32_t(c[1]), uint32_t(c[2])));
                    continue;
                }
                int64_t lo[3], hi[3];
                taps(c[0], in.x, lo[0], hi[0]), taps(c[1], in.y, lo[1], hi[1]), taps(c[2], in.z, lo[2], hi[2]);
                double sum = 0, total = 0, min = INFINITY, max = -INFINITY;
                for (int64_t k = lo[2]; k <= hi[2]; ++k)
                    for (int64_t j = lo[1]; j <= hi[1]; ++j)
                        for (int64_t i = lo[0]; i <= hi[0]; ++i) {
                            const double value = double(v.at(uint32_t(i), uint32_t(j), uint32_t(k)));
                            const double w = weight(i, c[0]) * weight(j, c[1]) * weight(k, c[2]);
                            sum += w * value, total += w;
                            min = std::min(min, value), max = std::max(max, value);
                        }
                o = float(rule == 1 ? sum / total : 0.5 * (min + max));
            }
    });
    return out;
}

const char* const kRuleNames[3] = {"decimate", "box mean", "range midpoint"};

double min_of(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

/// A factor's first frame from a cold page cache: the fastest round's frame (wall seconds), its
/// open-to-first-frame and what that run left resident of the file.
struct ColdFrame {
    double seconds = 0, open_to_frame = 0;
    uint64_t resident = 0;
};

/// `rounds` rounds (each factor once, the first rotating) of: drop the file from the page cache,
/// then `octiso-render FILE --iso ISO --size N --lod F --json` in a child process, so that the
/// open, its default verification and the frame's page faults are a user's first frame's.
/// `mapped` is this process's own mapping of the file: its pages are released first, since the
/// kernel keeps a page in the cache while any process maps it. Empty when rounds is 0.
std::vector<ColdFrame> cold_frames(const OctFile& mapped, const std::string& path, double iso, int image, int threads,
                                   const std::vector<double>& factors, int rounds, const std::filesystem::path& work) {
    if (rounds == 0) return {};
    std::vector<ColdFrame> best(factors.size());
    const std::string out = (work / "cold.png").string();
    const std::string size = std::to_string(image) + "x" + std::to_string(image);
    for (int round = 0; round < rounds; ++round)
        for (size_t i = 0; i < factors.size(); ++i) {
            const size_t k = (i + size_t(round)) % factors.size();
            mapped.release_resident_pages();
            evict_page_cache(path);
            const std::string json = run_tool("octiso-render", {path, "--iso", fmt(iso, 6), "--size", size, "--lod", fmt(factors[k], 6),
                                                                "--threads", std::to_string(threads), "--json", "-o", out});
            const double seconds = json_number(json, "frame_seconds");
            if (round == 0 || seconds < best[k].seconds)
                best[k] = {seconds, json_number(json, "open_to_first_frame_seconds"), uint64_t(json_number(json, "file_resident_bytes"))};
        }
    std::error_code ec;
    std::filesystem::remove(out, ec);
    return best;
}

int run_lod(cli::Args& args) {
    if (args.flag("--help")) {
        std::cout << kLodUsage << "\n";
        return 0;
    }
    const bool quick = args.flag("--quick"), markdown = args.flag("--markdown"), no_plot = args.flag("--no-plot");
    const bool rules = args.flag("--rules");
    const std::string mri_dir = args.value("--mri-dir").value_or("/usr/share/mricron/templates");
    auto specs = parse_dataset_specs(
        args.value("--dataset").value_or(quick ? "plume:64@40.5"
                                               : "plume:1024@40.5,mixing:1024@127.5,ch2better.nii.gz@100.5,ch2better.nii.gz@25.5"),
        mri_dir);
    for (DatasetSpec& s : specs)
        if (s.is_oct) s.name = std::filesystem::path(s.name).filename().string();   // the table's label
    std::vector<double> factors{0};
    for (double f : cli::parse_list(args.value("--lod").value_or(quick ? "1,4" : "0.5,1,2,4"), "--lod")) {
        if (!(f > 0) || !std::isfinite(f)) throw Error("--lod", "factors must be finite and > 0 (0, the exact frame, is always run)");
        factors.push_back(f);
    }
    std::vector<int> images;
    for (double v : cli::parse_list(args.value("--image").value_or(quick ? "128" : "512,1024"), "--image")) images.push_back(int(v));
    std::vector<std::string> views;
    {
        const std::string text = args.value("--view").value_or("whole,close");
        for (size_t p = 0; p <= text.size();) {
            const size_t c = std::min(text.find(',', p), text.size());
            views.push_back(text.substr(p, c - p));
            if (views.back() != "whole" && views.back() != "close" && views.back() != "near")
                throw Error("--view", "expected whole, close or near, found '" + views.back() + "'");
            p = c + 1;
        }
    }
    const int threads = int(cli::parse_int(args.value("--threads").value_or("1"), "--threads", 1, 1024));
    const int repeats = int(cli::parse_int(args.value("--repeats").value_or(quick ? "1" : "3"), "--repeats", 1, 1000));
    const int cold_rounds = int(cli::parse_int(args.value("--cold").value_or("0"), "--cold", 0, 1000));
    const std::optional<std::string> work_flag = args.value("--work");
    const std::optional<std::string> tag = args.value("--tag");
    const std::string results = results_dir(args);
    args.finish();
    const std::filesystem::path work =
        work_flag ? std::filesystem::path(*work_flag)
                  : std::filesystem::temp_directory_path() / ("octiso-bench-lod-" + std::to_string(::getpid()));
    std::filesystem::create_directories(work);
    struct RemoveWork {
        std::filesystem::path path;
        bool owned;
        ~RemoveWork() {
            std::error_code ec;
            if (owned) std::filesystem::remove_all(path, ec);
        }
    } remove_work{work, !work_flag};

    std::vector<CaseRow> cases;
    std::vector<RuleRow> rule_rows;
    std::map<std::string, std::string> converted;   // source -> .oct
    for (const DatasetSpec& spec : specs) {
        std::string path = spec.source;
        if (!spec.is_oct) {
            if (!converted.count(spec.source)) {
                std::string stem = spec.name;
                for (char& c : stem) if (c == ':' || c == '/' || c == '.') c = '_';
                const std::string out = (work / (stem + ".oct")).string();
                std::cerr << "converting " << spec.source << "\n";
                run_tool("octiso-convert", spec.is_synthetic ? std::vector<std::string>{"--synthetic", spec.source, "-o", out}
                                                             : std::vector<std::string>{spec.source, "-o", out});
                converted[spec.source] = out;
            }
            path = converted[spec.source];
        }
        const AnyOctree tree = AnyOctree::open(path);
        const AnyOctreeInfo info = tree.info();
        const double voxel = std::min({std::fabs(info.placement.spacing[0]), std::fabs(info.placement.spacing[1]),
                                       std::fabs(info.placement.spacing[2])});
        const double widest = std::max({std::fabs(info.placement.spacing[0]), std::fabs(info.placement.spacing[1]),
                                        std::fabs(info.placement.spacing[2])});
        std::cerr << "== " << spec.name << " iso " << spec.iso << "\n";
        for (int image : images)
            for (const std::string& view : views) {
                Camera camera = frame_data_box(info.dims, info.placement, image, image);
                if (view == "close") camera.fov_deg = 2 * std::atan(std::tan(camera.fov_deg * M_PI / 360) / 8) * 360 / M_PI;
                if (view == "near")
                    for (int a = 0; a < 3; ++a) camera.eye[a] = camera.look[a] + (camera.eye[a] - camera.look[a]) / 2;
                double centre_distance = 0;
                for (int a = 0; a < 3; ++a) {
                    const double c = camera.look[a] - camera.eye[a];
                    centre_distance += c * c;
                }
                const double pixel = 2 * std::tan(camera.fov_deg * M_PI / 360) / image;   // lod.h's width per distance
                const double footprint = pixel * std::sqrt(centre_distance) / widest;
                std::vector<std::shared_ptr<Renderer>> renderers;
                for (double f : factors) {
                    RenderOptions o;
                    o.isovalues = {spec.iso};
                    o.want_colour = false, o.want_depth = true, o.want_normal = true;
                    o.threads = threads;
                    o.lod = f;
                    renderers.push_back(std::make_shared<Renderer>(tree.make_renderer(o)));
                }
                auto frame_of = [&](size_t k, Frame& out) {
                    const double c0 = thread_cpu_seconds();
                    renderers[k]->render(camera, out);
                    return threads == 1 ? thread_cpu_seconds() - c0 : out.stats.seconds;
                };
                // Bytes touched first, from no resident page (each factor alone), then the frames.
                std::vector<uint64_t> touched(factors.size());
                for (size_t k = 0; k < factors.size(); ++k) {
                    tree.file()->release_resident_pages();
                    Frame f;
                    frame_of(k, f);
                    touched[k] = mapped_resident_bytes(path);
                }
                std::vector<Frame> frames(factors.size());
                for (size_t k = 0; k < factors.size(); ++k) frame_of(k, frames[k]);
                std::vector<std::vector<double>> seconds(factors.size());
                for (int round = 0; round < repeats; ++round)
                    for (size_t i = 0; i < factors.size(); ++i) {
                        const size_t k = (i + size_t(round)) % factors.size();
                        Frame f;
                        seconds[k].push_back(frame_of(k, f));
                    }
                const std::vector<ColdFrame> cold =
                    view == "whole" ? cold_frames(*tree.file(), path, spec.iso, image, threads, factors, cold_rounds, work)
                                    : std::vector<ColdFrame>{};
                for (size_t k = 0; k < factors.size(); ++k) {
                    CaseRow r;
                    if (!cold.empty()) {
                        r.cold_seconds = cold[k].seconds, r.cold_speedup = cold[0].seconds / cold[k].seconds;
                        r.cold_resident = cold[k].resident, r.cold_open_to_frame = cold[k].open_to_frame;
                    }
                    r.dataset = spec.name, r.view = view, r.iso = spec.iso, r.footprint = footprint, r.lod = factors[k];
                    r.image = image;
                    r.seconds = min_of(seconds[k]);
                    r.speedup = min_of(seconds[0]) / r.seconds;
                    r.touched = touched[k], r.file_bytes = tree.file()->file_bytes();
                    r.error = compare(frames[k], frames[0], voxel);
                    for (size_t b = 0; b < frames[k].stats.hits_by_cell_log2.size(); ++b)
                        if (frames[k].stats.hits_by_cell_log2[b]) r.hit_depths[info.dmax - int(b)] = frames[k].stats.hits_by_cell_log2[b];
                    cases.push_back(r);
                }
            }
        if (rules) {
            const LoadedVolume dense = open_dense(spec);
            if (dense.empty()) continue;
            const std::vector<uint32_t> units = quick ? std::vector<uint32_t>{2} : std::vector<uint32_t>{2, 4, 8};
            const Camera camera = frame_data_box(info.dims, info.placement, images.front(), images.front());
            RenderOptions o;
            o.isovalues = {spec.iso};
            o.want_colour = false, o.want_depth = true, o.want_normal = true;
            o.threads = threads;
            dispatch_scalar_type(dense.type(), [&](auto tag) {
                using T = decltype(tag);
                // Cropped to k 8 + 1 voxels per axis, so that every rule's lattice ends on the last
                // voxel and the border (which --lod cuts to the last voxel) plays no part; the
                // reference is the exact frame of the cropped array.
                const VolumeView<T> full = dense.view<T>();
                const uint32_t top = units.back();
                const Dims cd{(full.dims.x - 1) / top * top + 1, (full.dims.y - 1) / top * top + 1, (full.dims.z - 1) / top * top + 1};
                std::vector<T> cropped(cd.voxels());
                for (uint32_t z = 0; z < cd.z; ++z)
                    for (uint32_t y = 0; y < cd.y; ++y)
                        for (uint32_t x = 0; x < cd.x; ++x) cropped[x + uint64_t(cd.x) * (y + uint64_t(cd.y) * z)] = full.at(x, y, z);
                VolumeView<T> crop;
                crop.data = reinterpret_cast<const std::byte*>(cropped.data());
                crop.dims = cd;
                const Frame exact = AnyOctree::build(crop, info.placement, BuildOptions{}).render(camera, o);
                for (uint32_t u : units)
                    for (int rule = 0; rule < 3; ++rule) {
                        Dims d;
                        const std::vector<float> coarse = reduce(crop, u, rule, d);
                        VolumeView<float> cv;
                        cv.data = reinterpret_cast<const std::byte*>(coarse.data());
                        cv.dims = d;
                        Placement p = info.placement;
                        for (double& sp : p.spacing) sp *= u;
                        const Frame f = AnyOctree::build(cv, p, BuildOptions{}).render(camera, o);
                        rule_rows.push_back({spec.name, kRuleNames[rule], spec.iso, u, compare(f, exact, voxel)});
                    }
            });
        }
    }

    auto depths_text = [](const CaseRow& r) {
        uint64_t hits = 0;
        for (const auto& [d, n] : r.hit_depths) hits += n;
        std::string s;
        for (auto it = r.hit_depths.rbegin(); it != r.hit_depths.rend(); ++it)
            if (double(it->second) >= 0.005 * double(hits))
                s += (s.empty() ? "" : " ") + std::to_string(it->first) + ":" + fmt(100.0 * double(it->second) / double(hits), 0) + "%";
        return s.empty() ? std::string("-") : s;
    };
    Table table({"dataset", "iso", "image", "view", "px/voxel", "lod", "ms", "speed-up", "mask mismatch", "holes", "depth err med/p99/max",
                 "normal err med/p99 deg", "touched MiB", "of file", "hits by depth", "identical", "cold ms", "cold speed-up"});
    for (const CaseRow& r : cases)
        table.add({r.dataset, fmt(r.iso, 1), std::to_string(r.image) + "^2", r.view, fmt(r.footprint, 2), fmt(r.lod, 1),
                   fmt(r.seconds * 1e3, 1), fmt(r.speedup, 2) + " x", fmt(100 * r.error.mismatch, 3) + " %", std::to_string(r.error.holes),
                   fmt(r.error.depth_median, 3) + " / " + fmt(r.error.depth_p99, 3) + " / " + fmt(r.error.depth_max, 2),
                   fmt(r.error.normal_median, 2) + " / " + fmt(r.error.normal_p99, 1), fmt(double(r.touched) / 1048576.0, 1),
                   fmt(100.0 * double(r.touched) / double(r.file_bytes), 1) + " %", depths_text(r), r.error.identical ? "yes" : "no",
                   r.cold_seconds > 0 ? fmt(r.cold_seconds * 1e3, 1) : "-", r.cold_seconds > 0 ? fmt(r.cold_speedup, 2) + " x" : "-"});
    std::cout << "level of detail against the exact frame (min of " << repeats << " rounds, interleaved; " << threads
              << (threads == 1 ? " thread: thread CPU time" : " threads: wall") << "; depth + normals; " << machine_description()
              << ")\npx/voxel = pixel footprint at the data centre in voxels of the widest axis; mask mismatch over the exact "
                 "frame's hits; errors in voxels of the finest axis; touched = the file's pages resident after one frame from none;\n"
                 "cold = octiso-render's first frame after the file left the page cache (wall, min of --cold rounds; whole view)\n";
    if (markdown) table.print_markdown(std::cout);
    else table.print(std::cout);
    if (!rule_rows.empty()) {
        Table t({"dataset", "iso", "unit", "rule", "mask mismatch", "depth err med/p99/max", "normal err med/p99 deg"});
        for (const RuleRow& r : rule_rows)
            t.add({r.dataset, fmt(r.iso, 1), std::to_string(r.unit), r.rule, fmt(100 * r.error.mismatch, 3) + " %",
                   fmt(r.error.depth_median, 3) + " / " + fmt(r.error.depth_p99, 3) + " / " + fmt(r.error.depth_max, 2),
                   fmt(r.error.normal_median, 2) + " / " + fmt(r.error.normal_p99, 1)});
        std::cout << "\nrepresentative value of a coarse level: the array reduced to unit u by each rule, traced exactly, "
                     "against the exact frame (whole view, "
                  << images.front() << "^2)\n";
        if (markdown) t.print_markdown(std::cout);
        else t.print(std::cout);
    }

    auto error_json = [](cli::JsonWriter& j, const FrameError& e) {
        j.field("exact_hits", int64_t(e.exact_hits)).field("mismatched", int64_t(e.mismatched)).field("mismatch", e.mismatch);
        j.field("holes", int64_t(e.holes));
        j.field("depth_error_median", e.depth_median).field("depth_error_p99", e.depth_p99).field("depth_error_max", e.depth_max);
        j.field("normal_error_median_deg", e.normal_median).field("normal_error_p99_deg", e.normal_p99);
        j.field("identical", e.identical);
    };
    const std::string path = write_json(results, tag ? "lod_" + *tag : std::string("lod"), [&](cli::JsonWriter& j) {
        j.begin_object();
        j.field("machine", machine_description()).field("repeats", int64_t(repeats)).field("threads", int64_t(threads));
        j.key("cases").begin_array();
        for (const CaseRow& r : cases) {
            j.begin_object().field("dataset", r.dataset).field("iso", r.iso).field("image", int64_t(r.image)).field("view", r.view);
            j.field("footprint_voxels", r.footprint).field("lod", r.lod).field("seconds", r.seconds).field("speedup", r.speedup);
            j.field("touched_bytes", int64_t(r.touched)).field("file_bytes", int64_t(r.file_bytes));
            if (r.cold_seconds > 0) {
                j.field("cold_frame_seconds", r.cold_seconds).field("cold_speedup", r.cold_speedup);
                j.field("cold_open_to_first_frame_seconds", r.cold_open_to_frame).field("cold_resident_bytes", int64_t(r.cold_resident));
            }
            error_json(j, r.error);
            j.key("hit_depths").begin_object();
            for (const auto& [d, n] : r.hit_depths) j.field(std::to_string(d), int64_t(n));
            j.end_object().end_object();
        }
        j.end_array();
        j.key("rules").begin_array();
        for (const RuleRow& r : rule_rows) {
            j.begin_object().field("dataset", r.dataset).field("iso", r.iso).field("unit", int64_t(r.unit)).field("rule", r.rule);
            error_json(j, r.error);
            j.end_object();
        }
        j.end_array();
        j.end_object();
    });
    std::cout << "wrote " << path << "\n";
    if (!no_plot) plot("lod", path, path.substr(0, path.size() - 5) + ".png");
    // The contract the tests also check: where F x the footprint stays below two voxels, the frame is the exact one.
    bool contract = true;
    for (const CaseRow& r : cases)
        if (r.lod > 0 && r.lod * r.footprint * 1.25 < 2 && r.view == "close" && !r.error.identical) contract = false;
    if (!contract) {
        std::cerr << "octiso-bench lod: a close-up frame below two voxels per F pixels differs from the exact frame\n";
        return 1;
    }
    return 0;
}

const bool kRegistered = register_bench("lod", "level of detail: frame time, bytes touched and image error (issue 14)", &run_lod);

}  // namespace
}  // namespace octiso::bench
