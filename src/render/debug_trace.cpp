// trace_pixel (octiso/debug_trace.h): the pixel's camera ray through an OctreeTracer whose
// recording policy appends one PixelTraceEvent per step, and the text `--debug-pixel` prints.
// Only this file instantiates the recording tracer; frames use NoRecorder (traverse.h).
#include "octiso/debug_trace.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "octiso/error.h"
#include "render/clip.h"
#include "render/pinhole_camera.h"
#include "render/roots.h"
#include "render/traverse.h"

namespace octiso {
namespace {

using Kind = PixelTraceEvent::Kind;

/// The recording policy of OctreeTracer: appends to a log the caller owns. Per-ray allocation is
/// fine here: this tracer only ever traces one ray.
struct PixelTraceRecorder {
    static constexpr bool kOn = true;
    std::vector<PixelTraceEvent>* log = nullptr;

    void push(const PixelTraceEvent& e) const { log->push_back(e); }
    void clip(double t_in, double t_out) const {
        PixelTraceEvent e;
        e.kind = Kind::clip, e.t0 = t_in, e.t1 = t_out;
        push(e);
    }
    void enter_node(int d, uint32_t index, const Coord& o, uint32_t side, double t0, double t1) const {
        push({Kind::node, d, index, o, side, t0, t1});
    }
    void cull(int d, int c, const Coord& o, uint32_t side, double lo, double hi, double t0, double t1) const {
        push({Kind::cull, d, uint32_t(c), o, side, t0, t1, lo, hi});
    }
    void scalar_leaf(int d, const Coord& o, uint32_t side, double value, double t0, double t1, bool all_cells) const {
        push({Kind::scalar_leaf, d, 0, o, side, t0, t1, value, value, all_cells});
    }
    /// `parent`: the index of the cap's parent at depth dmax-2 (caps are byte offsets, octree.h).
    void enter_cap(int d, uint32_t parent, const Coord& o, double t0, double t1) const {
        push({Kind::cap, d, parent, o, 2, t0, t1});
    }
    void cell(const Coord& v, double t_in, double t_out, bool closed_end, double lo, double hi) const {
        push({Kind::cell, -1, 0, v, 1, t_in, t_out, lo, hi, closed_end});
    }
    void root(double t, int iso_index) const {
        PixelTraceEvent e;
        e.kind = Kind::root, e.t0 = e.t1 = t, e.iso_index = iso_index;
        push(e);
    }
};

std::string format(const char* fmt, auto... args) {
    char buf[512];
    std::snprintf(buf, sizeof buf, fmt, args...);
    return buf;
}

std::string coord_text(const Coord& c) { return format("(%u,%u,%u)", c.x, c.y, c.z); }

}  // namespace

std::string PixelTrace::text() const {
    std::string s = format("pixel (%d,%d) of %dx%d: world ray origin (%.17g, %.17g, %.17g) dir (%.17g, %.17g, %.17g)\n",
                           x, y, width, height, origin[0], origin[1], origin[2], dir[0], dir[1], dir[2]);
    // Containers indent by depth; cells and roots one step inside the last container.
    int inner = 0;
    for (const PixelTraceEvent& e : events) {
        int level = inner;
        std::string line;
        switch (e.kind) {
            case Kind::clip:
                line = e.t0 <= e.t1 ? format("data box: t [%.17g, %.17g]", e.t0, e.t1) : std::string("data box: missed");
                break;
            case Kind::node:
                level = e.depth, inner = e.depth + 1;
                line = format("node depth %d #%u origin %s side %u t [%.17g, %.17g)", e.depth, e.index,
                              coord_text(e.origin).c_str(), e.side, e.t0, e.t1);
                break;
            case Kind::cull:
                level = e.depth + 1;
                line = format("cull child %u origin %s side %u range [%.9g, %.9g] t [%.17g, %.17g)", e.index,
                              coord_text(e.origin).c_str(), e.side, e.lo, e.hi, e.t0, e.t1);
                break;
            case Kind::scalar_leaf:
                level = e.depth + 1, inner = e.depth + 2;
                line = format("scalar leaf origin %s side %u value %.9g%s t [%.17g, %.17g)", coord_text(e.origin).c_str(),
                              e.side, e.lo, e.closed_end ? " (an isovalue equals it: every cell)" : " (shell cells)",
                              e.t0, e.t1);
                break;
            case Kind::cap:
                level = e.depth, inner = e.depth + 1;
                line = format("cap under node #%u origin %s t [%.17g, %.17g)", e.index, coord_text(e.origin).c_str(), e.t0, e.t1);
                break;
            case Kind::cell:
                line = format("cell %s t [%.17g, %.17g%s corners [%.9g, %.9g]", coord_text(e.origin).c_str(), e.t0, e.t1,
                              e.closed_end ? "]" : ")", e.lo, e.hi);
                break;
            case Kind::root:
                level = inner + 1;
                line = format("root t %.17g iso %d (%.9g)", e.t0, e.iso_index,
                              e.iso_index >= 0 && size_t(e.iso_index) < isovalues.size() ? isovalues[size_t(e.iso_index)] : NAN);
                break;
        }
        s += std::string(size_t(2 * level), ' ') + line + "\n";
    }
    if (iso_index >= 0)
        s += format("hit t %.17g iso %d (%.9g) normal (%.9g, %.9g, %.9g)\n", t, iso_index, isovalues[size_t(iso_index)],
                    normal[0], normal[1], normal[2]);
    else
        s += "miss\n";
    return s;
}

template <typename T>
PixelTrace trace_pixel(const Octree<T>& tree, const Placement& placement, const Camera& camera,
                       const RenderOptions& options, int x, int y) {
    validate_options(options);
    validate_camera(camera);
    if (x < 0 || x >= camera.width || y < 0 || y >= camera.height)
        throw Error("--debug-pixel", "pixel (" + std::to_string(x) + "," + std::to_string(y) + ") lies outside the " +
                                         std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                                         " image (expected 0 <= X < " + std::to_string(camera.width) +
                                         ", 0 <= Y < " + std::to_string(camera.height) + ")");
    PixelTrace out;
    out.x = x, out.y = y, out.width = camera.width, out.height = camera.height;
    out.isovalues = options.isovalues;
    Ray ray = PinholeCamera(camera).ray(x, y);
    clip_ray(options.clip_planes, ray);   // the interval the frame traces (render/clip.h)
    out.origin = ray.origin, out.dir = ray.dir;
    dispatch_root_finder(options.root_finder, options.iterations, [&](const auto& finder) {
        using Finder = std::decay_t<decltype(finder)>;
        const OctreeTracer<T, Finder, OctreeCornerSource, PixelTraceRecorder> tracer(
            tree, placement, options.isovalues.data(), int(options.isovalues.size()), finder, OctreeCornerSource{},
            PixelTraceRecorder{&out.events});
        const TraceHit hit = tracer.trace(ray, true);
        out.t = hit.t, out.iso_index = hit.iso_index, out.normal = hit.normal;
    });
    return out;
}

#define OCTISO_INSTANTIATE(T)                                                                               \
    template PixelTrace trace_pixel<T>(const Octree<T>&, const Placement&, const Camera&, const RenderOptions&, \
                                       int, int);
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)
#undef OCTISO_INSTANTIATE

}  // namespace octiso
