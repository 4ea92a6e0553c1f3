// octiso-bench packets (issue 11): what coherent packet traversal buys, per change, against the
// triangle BVH a user would otherwise extract. For each dataset, image size and thread count,
// interleaved in one run (each round renders every method once, the first method rotating):
//   octiso single, Embree  - the previous default: Embree rtcIntersect8, each lane traced alone
//   octiso single          - one ray at a time, called directly (baseline build)
//   octiso packets         - 16-ray packets of 4x4 pixels, called directly, portable x86-64-v2 kernel
//   octiso packets AVX2    - the same, AVX2 kernel (when the CPU has it)
//   octiso packets, Embree - the default path: Embree rtcIntersect8 hands its packet to the kernel
//   mesh 1-ray / 8-ray / 16-ray - vtkFlyingEdges3D + Embree HIGH robust, rtcIntersect1 / rtcIntersect8 over
//                            8x1 rows and over 4x2 blocks / rtcIntersect16 over 4x4 blocks (the mesh's
//                            best packet shape is its number)
// Every octiso frame (depth and normal) is compared bit for bit with the single-ray one. Then the
// packet threshold (lanes below which a packet splits into single rays) is swept, and incoherent
// rays (random origins inside the data, random directions) are traced alone and in packets.
// Times: minimum over the repeats of the frame's wall time (1 thread: the thread's CPU time, which
// other processes on this shared machine do not inflate).
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <map>
#include <random>
#include <vector>

#include "bench/bench.h"
#include "bench/dataset_spec.h"
#include "bench/peers_mesh.h"
#include "octiso/any_octree.h"
#include "octiso/error.h"
#include "octiso/reader.h"
#include "octiso/render.h"
#include "octiso/synthetic.h"
#include "render/tracer_kernel.h"

namespace octiso::bench {
namespace {

const char* const kPacketsUsage =
    "usage: octiso-bench packets [--dataset SPEC[,SPEC...]] [--image 512,1024] [--threads 1,2] [--repeats N]\n"
    "                            [--mri-dir DIR] [--no-mesh] [--quick] [--markdown] [--results DIR] [--no-plot]\n"
    "  SPEC: FILE@ISO (a file in --mri-dir, default /usr/share/mricron/templates) or NAME:N@ISO (plume, mixing)\n"
    "  default: ch2, ch2bet, ch2better at 100.5 and 25.5, aal.nii.gz@0.5, plume:256@40.5, mixing:256@127.5;\n"
    "  --quick: plume:48@40.5, 128x128, 1 thread, 2 repeats";

struct Method {
    std::string name;
    std::function<double(Frame*)> render;   ///< one frame; returns seconds (CPU at 1 thread)
    bool octiso = true;
    std::vector<double> seconds;
    bool identical = true;   ///< depth and normals bit-identical to the single-ray frame
};

bool same_frame(const Frame& a, const Frame& b) {
    return a.depth.size() == b.depth.size() && a.normal.size() == b.normal.size() &&
           std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)) == 0 &&
           std::memcmp(a.normal.data(), b.normal.data(), a.normal.size() * sizeof(float)) == 0;
}

double min_of(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

struct CaseRow {
    std::string dataset;
    double iso = 0;
    int image = 0, threads = 0;
    uint64_t hits = 0;
    std::vector<std::pair<std::string, double>> min_seconds;   // method -> min seconds
    std::vector<std::pair<std::string, bool>> identical;
};

struct ThresholdRow {
    std::string dataset;
    double iso = 0;
    std::vector<std::pair<int, double>> min_seconds;
};

struct IncoherentRow {
    std::string dataset;
    uint64_t rays = 0, hits = 0;
    double single_s = 0, packet_s = 0;
    bool identical = true;
};

/// Random rays from inside the data box in random directions, traced one by one and in packets of
/// kMaxTracePacket (the renderer's direct packets) through the same kernel; hits compared exactly.
template <typename T>
IncoherentRow incoherent(const std::string& name, const Octree<T>& tree, const Placement& placement, double iso,
                         uint64_t count, int repeats) {
    RenderOptions o;
    o.isovalues = {iso};
    const TracerKernel kernel = make_tracer_kernel(tree, placement, o, Isa::automatic);
    std::mt19937_64 rng(12345);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Dims d = tree.dims();
    const double n[3] = {double(d.x - 1), double(d.y - 1), double(d.z - 1)};
    std::vector<Ray> rays(count);
    for (Ray& r : rays) {
        for (int a = 0; a < 3; ++a) r.origin[a] = placement.origin[a] + u(rng) * n[a] * placement.spacing[a];
        const double z = 2 * u(rng) - 1, phi = 2 * M_PI * u(rng), s = std::sqrt(1 - z * z);
        r.dir = {s * std::cos(phi), s * std::sin(phi), z};
    }
    std::vector<TraceHit> single(count), packed(count);
    IncoherentRow row;
    row.dataset = name;
    row.rays = count;
    row.single_s = row.packet_s = INFINITY;
    for (int rep = 0; rep < repeats; ++rep) {
        double t0 = thread_cpu_seconds();
        for (uint64_t i = 0; i < count; ++i) single[i] = kernel.trace(kernel.user, rays[i], true);
        row.single_s = std::min(row.single_s, thread_cpu_seconds() - t0);
        t0 = thread_cpu_seconds();
        for (uint64_t i = 0; i < count; i += kMaxTracePacket)
            kernel.trace_packet(kernel.user, &rays[i], int(std::min<uint64_t>(kMaxTracePacket, count - i)), nullptr, true,
                                &packed[i]);
        row.packet_s = std::min(row.packet_s, thread_cpu_seconds() - t0);
    }
    for (uint64_t i = 0; i < count; ++i) {
        row.hits += single[i].is_hit();
        if (single[i].iso_index != packed[i].iso_index || std::memcmp(&single[i].t, &packed[i].t, sizeof(double)) != 0 ||
            single[i].normal != packed[i].normal)
            row.identical = false;
    }
    return row;
}

int run_packets(cli::Args& args) {
    if (args.flag("--help")) {
        std::cout << kPacketsUsage << "\n";
        return 0;
    }
    const bool quick = args.flag("--quick"), no_mesh = args.flag("--no-mesh"), markdown = args.flag("--markdown");
    const bool no_plot = args.flag("--no-plot");
    const std::string mri_dir = args.value("--mri-dir").value_or("/usr/share/mricron/templates");
    const std::string default_specs =
        quick ? "plume:48@40.5"
              : "ch2.nii.gz@100.5,ch2.nii.gz@25.5,ch2bet.nii.gz@100.5,ch2bet.nii.gz@25.5,ch2better.nii.gz@100.5,"
                "ch2better.nii.gz@25.5,aal.nii.gz@0.5,plume:256@40.5,mixing:256@127.5";
    const auto specs = parse_dataset_specs(args.value("--dataset").value_or(default_specs), mri_dir);
    std::vector<int> images, thread_counts;
    for (double v : cli::parse_list(args.value("--image").value_or(quick ? "128" : "512"), "--image")) images.push_back(int(v));
    for (double v : cli::parse_list(args.value("--threads").value_or(quick ? "1" : "1,2"), "--threads"))
        thread_counts.push_back(int(v));
    const int repeats = int(cli::parse_int(args.value("--repeats").value_or(quick ? "2" : "5"), "--repeats", 1, 1000));
    const std::string results = results_dir(args);
    args.finish();
    const bool avx2 = cpu_has_avx2();

    std::vector<CaseRow> cases;
    std::vector<ThresholdRow> thresholds;
    std::vector<IncoherentRow> incoherents;
    std::map<std::string, bool> incoherent_done;
    bool all_identical = true;
    for (const DatasetSpec& spec : specs) {
        const LoadedVolume volume = open_dense(spec, 2048);
        const AnyOctree tree = AnyOctree::build(volume, BuildOptions{});
        std::cerr << "== " << spec.name << " iso " << spec.iso << "\n";
        std::optional<MeshPeerResult> mesh;
        for (int image : images) {
            const Camera camera = frame_data_box(volume.dims(), volume.placement(), image, image);
            if (!no_mesh) {
                MeshPeerOptions mo;
                mo.quality = BvhQuality::high;
                mo.robust = true;
                mesh = run_mesh_peer(volume, spec.iso, camera, mo);
            }
            for (int threads : thread_counts) {
                auto octiso_method = [&](const std::string& name, Traversal traversal, Isa isa, bool embree) {
                    RenderOptions o;
                    o.isovalues = {spec.iso};
                    o.want_colour = false, o.want_depth = true, o.want_normal = true;
                    o.traversal = traversal, o.isa = isa, o.use_embree = embree, o.threads = threads;
                    auto renderer = std::make_shared<Renderer>(tree.make_renderer(o));
                    return Method{name, [renderer, camera, threads](Frame* out) {
                                      Frame f;
                                      const double c0 = thread_cpu_seconds();
                                      renderer->render(camera, f);
                                      const double s = threads == 1 ? thread_cpu_seconds() - c0 : f.stats.seconds;
                                      if (out) *out = std::move(f);
                                      return s;
                                  },
                                  true, {}, true};
                };
                std::vector<Method> methods;
                methods.push_back(octiso_method("octiso single, Embree", Traversal::single, Isa::baseline, true));
                methods.push_back(octiso_method("octiso single", Traversal::single, Isa::baseline, false));
                methods.push_back(octiso_method("octiso packets", Traversal::packets, Isa::baseline, false));
                if (avx2) methods.push_back(octiso_method("octiso packets AVX2", Traversal::packets, Isa::avx2, false));
                methods.push_back(octiso_method("octiso packets, Embree", Traversal::packets, Isa::automatic, true));
                if (mesh) {
                    for (MeshRays rays : {MeshRays::single, MeshRays::packet8, MeshRays::packet8_block, MeshRays::packet16_block}) {
                        Method m{"mesh " + std::string(rays == MeshRays::single         ? "1-ray"
                                                       : rays == MeshRays::packet8       ? "8-ray"
                                                       : rays == MeshRays::packet8_block ? "8-ray 4x2"
                                                                                         : "16-ray 4x4"),
                                 [&mesh, rays, threads](Frame*) {
                                     tbb::task_arena arena(threads);
                                     double s = 0;
                                     arena.execute([&] {
                                         const double c0 = thread_cpu_seconds();
                                         const double wall = mesh->render(rays, nullptr);
                                         s = threads == 1 ? thread_cpu_seconds() - c0 : wall;
                                     });
                                     return s;
                                 },
                                 false, {}, true};
                        methods.push_back(m);
                    }
                }
                Frame reference;
                (void)methods[1].render(&reference);   // single-ray, also the warm-up of the data
                for (Method& m : methods) {
                    if (!m.octiso) continue;
                    Frame f;
                    (void)m.render(&f);
                    m.identical = same_frame(f, reference);
                    all_identical &= m.identical;
                }
                for (int round = 0; round < repeats; ++round)
                    for (size_t i = 0; i < methods.size(); ++i) {
                        Method& m = methods[(i + size_t(round)) % methods.size()];
                        m.seconds.push_back(m.render(nullptr));
                    }
                CaseRow row;
                row.dataset = spec.name, row.iso = spec.iso, row.image = image, row.threads = threads;
                for (size_t i = 0; i < reference.depth.size(); ++i) row.hits += std::isfinite(reference.depth[i]);
                for (const Method& m : methods) {
                    row.min_seconds.emplace_back(m.name, min_of(m.seconds));
                    if (m.octiso) row.identical.emplace_back(m.name, m.identical);
                }
                cases.push_back(row);
            }
        }
        // The packet threshold, 1 thread, the first image size, the default kernel, direct.
        if (!quick) {
            const Camera camera = frame_data_box(volume.dims(), volume.placement(), images[0], images[0]);
            ThresholdRow tr;
            tr.dataset = spec.name, tr.iso = spec.iso;
            std::vector<std::pair<int, std::shared_ptr<Renderer>>> rs;
            for (int lanes = 1; lanes <= 4; ++lanes) {
                RenderOptions o;
                o.isovalues = {spec.iso};
                o.want_colour = false, o.want_depth = true;
                o.use_embree = false, o.threads = 1, o.packet_min_lanes = lanes;
                rs.emplace_back(lanes, std::make_shared<Renderer>(tree.make_renderer(o)));
            }
            std::vector<std::vector<double>> secs(rs.size());
            for (int round = 0; round < repeats; ++round)
                for (size_t i = 0; i < rs.size(); ++i) {
                    const size_t k = (i + size_t(round)) % rs.size();
                    Frame f;
                    const double c0 = thread_cpu_seconds();
                    rs[k].second->render(camera, f);
                    secs[k].push_back(thread_cpu_seconds() - c0);
                }
            for (size_t k = 0; k < rs.size(); ++k) tr.min_seconds.emplace_back(rs[k].first, min_of(secs[k]));
            thresholds.push_back(tr);
        }
        if (!incoherent_done[spec.name]) {
            incoherent_done[spec.name] = true;
            dispatch_scalar_type(tree.type(), [&](auto tag) {
                using T = decltype(tag);
                const OctreeData<T> data = build_octree(volume.view<T>(), {});
                incoherents.push_back(
                    incoherent(spec.name, data.view(), volume.placement(), spec.iso, quick ? 4096 : 65536, quick ? 1 : 3));
            });
            all_identical &= incoherents.back().identical;
        }
    }

    // Tables.
    std::vector<std::string> header{"dataset", "iso", "image", "threads", "hits"};
    for (const auto& [name, s] : cases.front().min_seconds) header.push_back(name + " ms");
    header.push_back("packets/single");
    header.push_back("best mesh packets / best octiso");
    header.push_back("identical");
    Table table(header);
    for (const CaseRow& r : cases) {
        std::vector<std::string> cells{r.dataset, fmt(r.iso, 1), std::to_string(r.image) + "^2", std::to_string(r.threads),
                                       std::to_string(r.hits)};
        double best = INFINITY, mesh_packets = NAN, before = NAN;
        for (const auto& [name, s] : r.min_seconds) {
            cells.push_back(fmt(s * 1e3, 1));
            if (name == "octiso single, Embree") before = s;
            if (name.rfind("octiso packets", 0) == 0) best = std::min(best, s);
            if (name.rfind("mesh 8-ray", 0) == 0 || name.rfind("mesh 16-ray", 0) == 0)
                mesh_packets = std::isnan(mesh_packets) ? s : std::min(mesh_packets, s);
        }
        cells.push_back(fmt(before / best, 2) + " x");
        cells.push_back(std::isnan(mesh_packets) ? "-" : fmt(mesh_packets / best, 2) + " x");
        bool same = true;
        for (const auto& [name, ok] : r.identical) same &= ok;
        cells.push_back(same ? "yes" : "NO");
        table.add(cells);
    }
    std::cout << "packet traversal, frame time (min of " << repeats << ", interleaved; 1 thread: thread CPU time), depth + "
              << "normals, no shading (" << machine_description() << ")\n";
    std::cout << "packets/single = the previous default (single, Embree) / the fastest packet path; mesh = FE + Embree "
                 "HIGH robust; mesh / octiso = the fastest mesh packet row (8 or 16 rays) / the fastest octiso packet path (1 = parity)\n";
    if (markdown) table.print_markdown(std::cout);
    else table.print(std::cout);
    if (!thresholds.empty()) {
        Table t({"dataset", "iso", "min lanes 1 ms", "2 ms", "3 ms", "4 ms"});
        for (const ThresholdRow& r : thresholds) {
            std::vector<std::string> cells{r.dataset, fmt(r.iso, 1)};
            for (const auto& [lanes, s] : r.min_seconds) cells.push_back(fmt(s * 1e3, 1));
            t.add(cells);
        }
        std::cout << "\npacket threshold (a subtree entered by fewer lanes is traced by single rays), 1 thread, "
                  << images[0] << "^2, direct\n";
        if (markdown) t.print_markdown(std::cout);
        else t.print(std::cout);
    }
    Table ti({"dataset", "rays", "hits", "single ms", "packets ms", "packets/single", "identical"});
    for (const IncoherentRow& r : incoherents)
        ti.add({r.dataset, std::to_string(r.rays), std::to_string(r.hits), fmt(r.single_s * 1e3, 1), fmt(r.packet_s * 1e3, 1),
                fmt(r.packet_s / r.single_s, 3), r.identical ? "yes" : "NO"});
    std::cout << "\nincoherent rays (random origins inside the data, random directions), 1 thread, default kernel\n";
    if (markdown) ti.print_markdown(std::cout);
    else ti.print(std::cout);

    const std::string path = write_json(results, "packets", [&](cli::JsonWriter& j) {
        j.begin_object();
        j.field("machine", machine_description()).field("repeats", int64_t(repeats)).field("avx2", avx2);
        j.field("all_identical", all_identical);
        j.key("cases").begin_array();
        for (const CaseRow& r : cases) {
            j.begin_object().field("dataset", r.dataset).field("iso", r.iso).field("image", int64_t(r.image));
            j.field("threads", int64_t(r.threads)).field("hits", int64_t(r.hits));
            j.key("min_seconds").begin_object();
            for (const auto& [name, s] : r.min_seconds) j.field(name, s);
            j.end_object();
            j.key("identical").begin_object();
            for (const auto& [name, ok] : r.identical) j.field(name, ok);
            j.end_object().end_object();
        }
        j.end_array();
        j.key("thresholds").begin_array();
        for (const ThresholdRow& r : thresholds) {
            j.begin_object().field("dataset", r.dataset).field("iso", r.iso).key("min_seconds").begin_object();
            for (const auto& [lanes, s] : r.min_seconds) j.field(std::to_string(lanes), s);
            j.end_object().end_object();
        }
        j.end_array();
        j.key("incoherent").begin_array();
        for (const IncoherentRow& r : incoherents)
            j.begin_object().field("dataset", r.dataset).field("rays", int64_t(r.rays)).field("hits", int64_t(r.hits))
                .field("single_seconds", r.single_s).field("packet_seconds", r.packet_s).field("identical", r.identical)
                .end_object();
        j.end_array();
        j.end_object();
    });
    std::cout << "wrote " << path << "\n";
    if (!no_plot) plot("packets", path, path.substr(0, path.size() - 5) + ".png");
    if (!all_identical) {
        std::cerr << "octiso-bench packets: a packet or ISA path differs from the single-ray frame\n";
        return 1;
    }
    return 0;
}

const bool kRegistered = register_bench("packets", "packet traversal vs single rays vs the mesh (issue 11)", &run_packets);

}  // namespace
}  // namespace octiso::bench
