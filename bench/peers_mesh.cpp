// The extract-then-trace peer: vtkFlyingEdges3D (VTK's fastest extractor, TBB backend) -> Embree 3
// triangle BVH (robust or not, medium or high build quality) -> rtcIntersect8 packets along tile
// rows (coherent context) or rtcIntersect1, over the same TBB tiles (tile_size_for, as render())
// and the same PinholeCamera rays as octiso. Embree's own bytes are counted through its device
// memory monitor; the mesh buffers are ours and counted exactly.
#include "bench/peers_mesh.h"

#include <embree3/rtcore.h>
#include <tbb/parallel_for.h>
#include <vtkAOSDataArrayTemplate.h>
#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "bench/bench.h"
#include "octiso/error.h"
#include "render/pinhole_camera.h"
#include "render/tile_loop.h"
#include "util/huge_pages.h"

namespace octiso::bench {

std::string bvh_quality_name(BvhQuality q) { return q == BvhQuality::high ? "high" : "medium"; }
std::string mesh_rays_name(MeshRays r) {
    return r == MeshRays::packet8         ? "rtcIntersect8"
           : r == MeshRays::packet8_block ? "rtcIntersect8 4x2"
           : r == MeshRays::packet16_block ? "rtcIntersect16 4x4"
                                          : "rtcIntersect1";
}

namespace {

/// Embree's running allocation total. The monitor may be called concurrently from build threads.
struct MemoryMonitor {
    std::atomic<long long> bytes{0};
};

bool monitor_callback(void* user, ssize_t bytes, bool /*post*/) {
    static_cast<MemoryMonitor*>(user)->bytes += bytes;   // never cancels, so pre-calls are final
    return true;
}

/// The volume as VTK image data: origin and spacing from the placement (CONVENTIONS 1), so the
/// flying-edges vertices come out in world space. The voxels are shared, not copied, unless they
/// need a byte swap.
template <typename T>
vtkSmartPointer<vtkImageData> image_of(const LoadedVolume& volume, std::vector<T>& swapped) {
    const VolumeView<T> view = volume.view<T>();
    const Dims d = volume.dims();
    const T* voxels = reinterpret_cast<const T*>(view.data);
    if (view.swap_bytes || reinterpret_cast<uintptr_t>(view.data) % alignof(T) != 0) {
        swapped.resize(d.voxels());
        for (uint64_t i = 0; i < d.voxels(); ++i) swapped[i] = view.load(i);
        voxels = swapped.data();
    }
    auto image = vtkSmartPointer<vtkImageData>::New();
    image->SetDimensions(int(d.x), int(d.y), int(d.z));
    const Placement& p = volume.placement();
    image->SetSpacing(p.spacing[0], p.spacing[1], p.spacing[2]);
    image->SetOrigin(p.origin[0], p.origin[1], p.origin[2]);
    auto array = vtkSmartPointer<vtkAOSDataArrayTemplate<T>>::New();
    array->SetNumberOfComponents(1);
    // save = 1: VTK must not free our buffer. Flying edges only reads it, so the const_cast is safe.
    array->SetArray(const_cast<T*>(voxels), vtkIdType(d.voxels()), 1);
    array->SetName("scalars");
    image->GetPointData()->SetScalars(array);
    return image;
}

struct Mesh {
    std::vector<float> positions;   ///< 3 per vertex, plus one float of padding for Embree's 16-byte loads
    std::vector<uint32_t> indices;  ///< 3 per triangle
    std::vector<float> normals;     ///< 3 per vertex (vertex_normals only)
    uint64_t vertices = 0, triangles = 0;
};

/// Copies what flying edges produced into the buffers the renderer keeps (so VTK's poly data can
/// go); the copy is counted with the BVH build, the step that consumes it.
Mesh mesh_of(vtkPolyData* poly, bool vertex_normals) {
    Mesh m;
    m.vertices = uint64_t(poly->GetNumberOfPoints());
    m.positions.resize(3 * m.vertices + 1, 0.0f);
    if (m.vertices > 0) {
        vtkDataArray* points = poly->GetPoints()->GetData();
        if (auto* f = vtkAOSDataArrayTemplate<float>::SafeDownCast(points)) {
            std::copy(f->GetPointer(0), f->GetPointer(0) + 3 * m.vertices, m.positions.begin());
        } else {
            for (uint64_t i = 0; i < m.vertices; ++i) {
                double p[3];
                points->GetTuple(vtkIdType(i), p);
                for (int a = 0; a < 3; ++a) m.positions[3 * i + a] = float(p[a]);
            }
        }
    }
    if (vertex_normals) {
        vtkDataArray* n = poly->GetPointData()->GetNormals();
        if (!n || uint64_t(n->GetNumberOfTuples()) != m.vertices)
            throw Error("vtkFlyingEdges3D", "produced no vertex normals", ErrorKind::Other);
        m.normals.resize(3 * m.vertices);
        for (uint64_t i = 0; i < m.vertices; ++i) {
            double v[3];
            n->GetTuple(vtkIdType(i), v);
            for (int a = 0; a < 3; ++a) m.normals[3 * i + a] = float(v[a]);
        }
    }
    vtkCellArray* polys = poly->GetPolys();
    m.triangles = uint64_t(polys->GetNumberOfCells());
    const uint64_t ids = uint64_t(polys->GetNumberOfConnectivityIds());
    if (ids != 3 * m.triangles)
        throw Error("vtkFlyingEdges3D", "output is not all triangles (" + std::to_string(ids) + " ids for " +
                                            std::to_string(m.triangles) + " cells)", ErrorKind::Other);
    m.indices.resize(ids);
    if (polys->IsStorage64Bit()) {
        const auto* c = polys->GetConnectivityArray64()->GetPointer(0);
        for (uint64_t i = 0; i < ids; ++i) m.indices[i] = uint32_t(c[i]);
    } else {
        const auto* c = polys->GetConnectivityArray32()->GetPointer(0);
        for (uint64_t i = 0; i < ids; ++i) m.indices[i] = uint32_t(c[i]);
    }
    return m;
}

void throw_on_embree_error(RTCDevice device, const char* what) {
    const RTCError e = rtcGetDeviceError(device);
    if (e != RTC_ERROR_NONE) throw Error("embree", std::string(what) + " failed (error " + std::to_string(int(e)) + ")", ErrorKind::Other);
}

/// What stays alive between the frames of one mesh configuration: Embree's device and scene and
/// the buffers they share.
struct MeshScene {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    Mesh mesh;
    MeshScene() = default;
    MeshScene(const MeshScene&) = delete;
    MeshScene& operator=(const MeshScene&) = delete;
    ~MeshScene() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

/// One frame of `camera` through `ms` with `rays`; tile-loop seconds in frame.stats.seconds.
void render_mesh_frame(const MeshScene& ms, const Camera& camera, bool vertex_normals, MeshRays rays, Frame& frame,
                       Frame* geometric) {
    const PinholeCamera pinhole(camera);
    const int W = camera.width, H = camera.height;
    frame.width = W, frame.height = H;
    assign_on_huge_pages(frame.depth, size_t(W) * H, 0.0f);   // as octiso's frames (util/huge_pages.h)
    assign_on_huge_pages(frame.normal, size_t(W) * H * 3, 0.0f);
    if (geometric) {
        geometric->width = W, geometric->height = H;
        assign_on_huge_pages(geometric->normal, size_t(W) * H * 3, 0.0f);
    }
    const Mesh& mesh = ms.mesh;
    std::atomic<uint64_t> hits{0};
    // Unit length and facing the ray, as CONVENTIONS 2 asks of every normal AOV.
    auto store = [](const float* v, const Ray& ray, size_t i, std::vector<float>& out) {
        const float len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (!(len > 0)) {
            for (int a = 0; a < 3; ++a) out[3 * i + a] = -float(ray.dir[a]);
            return;
        }
        const float facing = v[0] * float(ray.dir[0]) + v[1] * float(ray.dir[1]) + v[2] * float(ray.dir[2]) > 0 ? -1.0f : 1.0f;
        for (int a = 0; a < 3; ++a) out[3 * i + a] = facing * v[a] / len;
    };
    // One hit (or miss) of pixel i: depth, and the chosen and geometric normals.
    auto shade = [&](const Ray& ray, size_t i, bool hit, float tfar, unsigned prim, float u, float v, const float ng[3]) {
        if (!hit) {
            frame.depth[i] = std::numeric_limits<float>::infinity();
            return false;
        }
        frame.depth[i] = tfar;
        float n[3] = {ng[0], ng[1], ng[2]};
        if (vertex_normals) {
            const uint32_t* tri = &mesh.indices[3 * size_t(prim)];
            const float w0 = 1.0f - u - v;
            for (int a = 0; a < 3; ++a)
                n[a] = w0 * mesh.normals[3 * tri[0] + a] + u * mesh.normals[3 * tri[1] + a] + v * mesh.normals[3 * tri[2] + a];
        }
        store(n, ray, i, frame.normal);
        if (geometric) store(ng, ray, i, geometric->normal);
        return true;
    };
    const int ts = tile_size_for(W, H, 0);   // the tile side render() uses for this frame
    const auto t0 = std::chrono::steady_clock::now();
    for_each_tile(  // render()'s tile loop over render()'s tiles
        TileGrid{W, H, ts}, {}, true,
        [&](const PixelRect& tile, TileCounters&) {
            uint64_t tile_hits = 0;
            RTCIntersectContext context;
            rtcInitIntersectContext(&context);
            if (rays != MeshRays::single) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
            // One packet of bw x bh pixels, one rtcIntersect8 / rtcIntersect16 call (RayHitN with N lanes).
            const auto trace_block = [&]<class RayHitN, int N>(int x0, int y0, int bw, int bh, auto intersect) {
                // The rays as render() makes them (PinholeCamera::block_rays, the same bits as ray()).
                const int w = std::min(bw, tile.x1 - x0), h = std::min(bh, tile.y1 - y0);
                const int count = w * h;
                Ray ray[N];
                size_t pixel[N];
                pinhole.block_rays(x0, y0, w, h, ray);
                for (int j = 0, k = 0; j < h; ++j)
                    for (int i = 0; i < w; ++i) pixel[k++] = size_t(y0 + j) * W + size_t(x0 + i);
                alignas(64) RayHitN rh{};
                alignas(64) int valid[N];
                for (int k = 0; k < N; ++k) {
                    valid[k] = k < count ? -1 : 0;
                    const Ray& r = ray[k < count ? k : 0];
                    rh.ray.org_x[k] = float(r.origin[0]), rh.ray.org_y[k] = float(r.origin[1]);
                    rh.ray.org_z[k] = float(r.origin[2]);
                    rh.ray.dir_x[k] = float(r.dir[0]), rh.ray.dir_y[k] = float(r.dir[1]);
                    rh.ray.dir_z[k] = float(r.dir[2]);
                    rh.ray.tnear[k] = 0.0f;
                    rh.ray.tfar[k] = std::numeric_limits<float>::infinity();
                    rh.ray.mask[k] = ~0u;   // Debian's Embree is built with ray masks: 0 would hit nothing
                    rh.ray.flags[k] = 0;
                    rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
                    rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
                }
                intersect(valid, ms.scene, &context, &rh);
                for (int k = 0; k < count; ++k) {
                    const float ng[3] = {rh.hit.Ng_x[k], rh.hit.Ng_y[k], rh.hit.Ng_z[k]};
                    tile_hits += shade(ray[k], pixel[k], rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID, rh.ray.tfar[k],
                                       rh.hit.primID[k], rh.hit.u[k], rh.hit.v[k], ng);
                }
            };
            if (rays == MeshRays::packet16_block) {
                // 4x4 blocks, one rtcIntersect16 each: the octree's own direct packet shape.
                for (int y0 = tile.y0; y0 < tile.y1; y0 += 4)
                    for (int x0 = tile.x0; x0 < tile.x1; x0 += 4)
                        trace_block.template operator()<RTCRayHit16, 16>(x0, y0, 4, 4, rtcIntersect16);
            } else if (rays != MeshRays::single) {
                // Packets of 8 pixels, one rtcIntersect8 each: runs of a tile row (8x1, as render()
                // fed Embree until issue 11) or 4x2 blocks (as render() does through Embree).
                const int bw = rays == MeshRays::packet8 ? 8 : 4, bh = 8 / bw;
                for (int y0 = tile.y0; y0 < tile.y1; y0 += bh)
                    for (int x0 = tile.x0; x0 < tile.x1; x0 += bw)
                        trace_block.template operator()<RTCRayHit8, 8>(x0, y0, bw, bh, rtcIntersect8);
            } else for (int py = tile.y0; py < tile.y1; ++py) {
                for (int px = tile.x0; px < tile.x1; ++px) {
                    const Ray ray = pinhole.ray(px, py);
                    RTCRayHit rh;
                    rh.ray.org_x = float(ray.origin[0]), rh.ray.org_y = float(ray.origin[1]), rh.ray.org_z = float(ray.origin[2]);
                    rh.ray.dir_x = float(ray.dir[0]), rh.ray.dir_y = float(ray.dir[1]), rh.ray.dir_z = float(ray.dir[2]);
                    rh.ray.tnear = 0.0f;
                    rh.ray.tfar = std::numeric_limits<float>::infinity();
                    rh.ray.time = 0.0f;
                    rh.ray.mask = ~0u;
                    rh.ray.id = 0;
                    rh.ray.flags = 0;
                    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
                    rtcIntersect1(ms.scene, &context, &rh);
                    const float ng[3] = {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
                    tile_hits += shade(ray, size_t(py) * W + px, rh.hit.geomID != RTC_INVALID_GEOMETRY_ID, rh.ray.tfar,
                                       rh.hit.primID, rh.hit.u, rh.hit.v, ng);
                }
            }
            hits += tile_hits;
        });
    frame.stats.seconds = seconds_since(t0);
    frame.stats.rays = uint64_t(W) * H;
    frame.stats.hits = hits;
    if (geometric) geometric->depth = frame.depth;
}

}  // namespace

MeshPeerResult run_mesh_peer(const LoadedVolume& volume, double iso, const Camera& camera, const MeshPeerOptions& options) {
    MeshPeerResult result;
    // No vtkSMPTools::Initialize here (its 9.1 header does not compile as C++20): VTK's TBB backend
    // follows the tbb::global_control the caller sets for --threads.

    // 1. Extraction. The image wrapper is set up before the clock starts: it shares the voxels.
    vtkNew<vtkFlyingEdges3D> flying_edges;
    {
        auto extract = [&](auto tag) {
            using T = decltype(tag);
            std::vector<T> swapped;
            vtkSmartPointer<vtkImageData> image = image_of<T>(volume, swapped);
            flying_edges->SetInputData(image);
            flying_edges->SetValue(0, iso);
            flying_edges->SetComputeNormals(options.vertex_normals);
            flying_edges->SetComputeGradients(false);
            flying_edges->SetComputeScalars(false);
            const auto t0 = std::chrono::steady_clock::now();
            flying_edges->Update();
            result.extract_seconds = seconds_since(t0);
            flying_edges->SetInputData(nullptr);   // `swapped` dies with this scope
        };
        dispatch_scalar_type(volume.type(), extract);
    }

    // 2. Upload and BVH build.
    auto ms = std::make_shared<MeshScene>();
    const std::string config = options.threads > 0 ? "threads=" + std::to_string(options.threads) : "";
    ms->device = rtcNewDevice(config.c_str());
    if (!ms->device) throw Error("embree", "rtcNewDevice failed", ErrorKind::Other);
    MemoryMonitor monitor;
    rtcSetDeviceMemoryMonitorFunction(ms->device, monitor_callback, &monitor);
    {
        const auto t0 = std::chrono::steady_clock::now();
        ms->mesh = mesh_of(flying_edges->GetOutput(), options.vertex_normals);
        flying_edges->GetOutput()->Initialize();   // the renderer keeps only `mesh`
        const Mesh& mesh = ms->mesh;
        ms->scene = rtcNewScene(ms->device);
        if (options.robust) rtcSetSceneFlags(ms->scene, RTC_SCENE_FLAG_ROBUST);
        const RTCBuildQuality quality = options.quality == BvhQuality::high ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM;
        rtcSetSceneBuildQuality(ms->scene, quality);
        if (mesh.triangles > 0) {
            RTCGeometry geometry = rtcNewGeometry(ms->device, RTC_GEOMETRY_TYPE_TRIANGLE);
            rtcSetGeometryBuildQuality(geometry, quality);
            rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, mesh.positions.data(), 0,
                                       3 * sizeof(float), size_t(mesh.vertices));
            rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh.indices.data(), 0,
                                       3 * sizeof(uint32_t), size_t(mesh.triangles));
            rtcCommitGeometry(geometry);
            rtcAttachGeometry(ms->scene, geometry);
            rtcReleaseGeometry(geometry);
        }
        rtcCommitScene(ms->scene);
        result.bvh_seconds = seconds_since(t0);
        throw_on_embree_error(ms->device, "building the triangle BVH");
    }
    // The monitor belongs to this frame: later frames allocate nothing, and it must not outlive us.
    result.bvh_bytes = uint64_t(std::max(0LL, monitor.bytes.load()));
    rtcSetDeviceMemoryMonitorFunction(ms->device, nullptr, nullptr);
    const Mesh& mesh = ms->mesh;
    result.vertices = mesh.vertices;
    result.triangles = mesh.triangles;
    result.mesh_bytes = (mesh.positions.size() + mesh.normals.size()) * sizeof(float) + mesh.indices.size() * sizeof(uint32_t);

    // 3. The first frame (packets, as render() does); the caller times the repeats through `render`.
    const auto t0 = std::chrono::steady_clock::now();
    render_mesh_frame(*ms, camera, options.vertex_normals, MeshRays::packet8, result.frame, &result.frame_geometric);
    result.first_render_seconds = seconds_since(t0);
    const bool vertex_normals = options.vertex_normals;
    result.render = [ms, camera, vertex_normals](MeshRays rays, Frame* out) {
        Frame scratch;
        Frame& f = out ? *out : scratch;
        render_mesh_frame(*ms, camera, vertex_normals, rays, f, nullptr);
        return f.stats.seconds;
    };
    return result;
}

}  // namespace octiso::bench
