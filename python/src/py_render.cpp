// Camera, Frame and Renderer for Python: a Renderer is the library's persistent Renderer (its
// Embree scene and thread arena are kept between frames: isovalue sweeps and orbits pay them
// once); Tree.render is the one-call form. A Frame's arrays adopt the rendered buffers (no copy).
// Isovalues are real values (CONVENTIONS 2b: a scaled NIfTI's stored * slope + inter), turned
// into the stored values the tree holds here, exactly as octiso-render turns its --iso.
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "octiso/any_octree.h"
#include "octiso/camera.h"
#include "octiso/error.h"
#include "octiso/render.h"

namespace octiso::python {
namespace {

std::array<int, 2> size_of(const py::object& size) {
    std::array<int, 2> wh{};
    try {
        const auto t = size.cast<std::array<long long, 2>>();
        for (int i = 0; i < 2; ++i) {
            if (t[i] < 1 || t[i] > 65536) throw py::value_error("");
            wh[size_t(i)] = int(t[i]);
        }
    } catch (const std::exception&) {
        throw py::value_error("size: expected (width, height) in pixels, each 1..65536");
    }
    return wh;
}

std::vector<double> isovalues_of(const py::object& iso) {
    if (py::isinstance<py::float_>(iso) || py::isinstance<py::int_>(iso)) return {iso.cast<double>()};
    try {
        return iso.cast<std::vector<double>>();
    } catch (const py::cast_error&) {
        throw py::value_error("iso: expected a number or a sequence of numbers");
    }
}

/// The stored isovalues of `tree` for the real ones `real` (ValueScale::stored, the tools' own
/// conversion, so a frame here equals octiso-render's for the same --iso). An iso-range is
/// checked here in real values, so the message names the numbers the caller gave; the Renderer
/// checks the same thing again on the stored ones.
std::vector<double> stored_isovalues(const AnyOctree& tree, const std::vector<double>& real) {
    const AnyOctreeInfo info = tree.info();
    std::vector<double> stored;
    for (const double v : real) {
        const double s = info.value_scale.stored(v);
        if (info.iso_range && std::isfinite(v) && !(s > (*info.iso_range)[0] && s < (*info.iso_range)[1])) {
            const std::array<double, 2> r = info.value_scale.real_range(*info.iso_range);
            throw Error("iso", "isovalue " + std::to_string(v) + " lies outside the iso-range (" + std::to_string(r[0]) + ", " +
                                   std::to_string(r[1]) + ") of " + info.source + " (real values)");
        }
        stored.push_back(s);
    }
    return stored;
}

RenderOptions options_of(const AnyOctree& tree, const std::vector<double>& real_iso, int threads, bool depth, bool normal,
                         const std::string& root_finder, int iterations, double lod) {
    if (threads < 0) throw py::value_error("threads: must be >= 0 (0: all cores)");
    RenderOptions o;
    o.isovalues = stored_isovalues(tree, real_iso);
    o.threads = threads;
    o.want_depth = depth;
    o.want_normal = normal;
    o.root_finder = parse_root_finder_name(root_finder);
    o.iterations = iterations;
    o.lod = lod;   // validated with the rest by the Renderer (ValueError naming --lod)
    return o;
}

/// The camera for a frame of w x h: the given one resized, or the default framing of `tree`.
Camera camera_for(const AnyOctree& tree, const std::optional<Camera>& camera, std::array<int, 2> wh) {
    const auto [w, h] = wh;
    if (camera) {
        Camera c = *camera;
        c.width = w, c.height = h;
        return c;
    }
    return frame_data_box(tree.dims(), tree.placement(), w, h);
}

/// A rendered frame as Python sees it: arrays that own the frame's buffers, and its statistics.
struct PyFrame {
    py::object rgb, depth, normal;
    RenderStats stats;
};

PyFrame to_python(Frame&& f) {
    PyFrame out;
    const py::ssize_t H = f.height, W = f.width;
    out.rgb = f.rgb.empty() ? py::object(py::none()) : py::object(array_owning(std::move(f.rgb), {H, W, 3}));
    out.depth = f.depth.empty() ? py::object(py::none()) : py::object(array_owning(std::move(f.depth), {H, W}));
    out.normal = f.normal.empty() ? py::object(py::none()) : py::object(array_owning(std::move(f.normal), {H, W, 3}));
    out.stats = f.stats;
    return out;
}

/// A Renderer with the Tree it reads (the Tree shares the octree's storage, so it stays valid).
struct PyRenderer {
    AnyOctree tree;
    Renderer renderer;
    std::array<int, 2> size;     ///< frame width, height
    std::vector<double> iso;     ///< the real isovalues as given (the renderer holds the stored ones)
};

}  // namespace

void bind_render(py::module_& m) {
    py::class_<Camera>(m, "Camera", "A perspective pinhole in world units (CONVENTIONS 2): eye, look, up, vertical fov in degrees.")
        .def(py::init([](const py::object& eye, const py::object& look, const py::object& up, double fov) {
                 Camera c;
                 c.eye = vec3_of(eye, "eye");
                 c.look = vec3_of(look, "look");
                 c.up = vec3_of(up, "up");
                 c.fov_deg = fov;
                 validate_camera(c);
                 return c;
             }),
             py::arg("eye"), py::arg("look"), py::arg("up") = py::make_tuple(0.0, 0.0, 1.0), py::arg("fov") = 40.0)
        .def_property("eye", [](const Camera& c) { return py::make_tuple(c.eye[0], c.eye[1], c.eye[2]); },
                      [](Camera& c, const py::object& v) { c.eye = vec3_of(v, "eye"); })
        .def_property("look", [](const Camera& c) { return py::make_tuple(c.look[0], c.look[1], c.look[2]); },
                      [](Camera& c, const py::object& v) { c.look = vec3_of(v, "look"); })
        .def_property("up", [](const Camera& c) { return py::make_tuple(c.up[0], c.up[1], c.up[2]); },
                      [](Camera& c, const py::object& v) { c.up = vec3_of(v, "up"); })
        .def_readwrite("fov", &Camera::fov_deg)
        .def_static("frame", [](const AnyOctree& tree, std::optional<double> azimuth, std::optional<double> elevation, double zoom,
                                const py::object& size) {
            const auto [w, h] = size_of(size);
            if (!azimuth && !elevation && zoom == 1.0) return frame_data_box(tree.dims(), tree.placement(), w, h);
            return orbit_camera(tree.dims(), tree.placement(), w, h, azimuth.value_or(kDefaultAzimuthDeg),
                                elevation.value_or(kDefaultElevationDeg), zoom);
        }, py::arg("tree"), py::arg("azimuth") = py::none(), py::arg("elevation") = py::none(), py::arg("zoom") = 1.0,
           py::arg("size") = py::make_tuple(512, 512),
           R"(A camera looking at the centre of tree's data box, z up: azimuth in degrees from +x in the xy plane,
elevation in degrees above it, at the distance where the box fills a frame of `size`, divided by zoom.
Without angles: the same three-quarter view as octiso-render without camera flags.)")
        .def("__repr__", [](const Camera& c) {
            return "<octiso.Camera eye=(" + std::to_string(c.eye[0]) + ", " + std::to_string(c.eye[1]) + ", " +
                   std::to_string(c.eye[2]) + ") fov=" + std::to_string(c.fov_deg) + ">";
        });

    py::class_<PyFrame>(m, "Frame", "One rendered image: rgb (uint8 HxWx3, sRGB), depth (float32 HxW, world t, inf on a miss) and normal (float32 HxWx3) where asked for, else None.")
        .def_readonly("rgb", &PyFrame::rgb)
        .def_readonly("depth", &PyFrame::depth)
        .def_readonly("normal", &PyFrame::normal)
        .def_property_readonly("seconds", [](const PyFrame& f) { return f.stats.seconds; }, "wall time of the tile loop")
        .def_property_readonly("rays", [](const PyFrame& f) { return f.stats.rays; })
        .def_property_readonly("hits", [](const PyFrame& f) { return f.stats.hits; })
        .def_property_readonly("threads", [](const PyFrame& f) { return f.stats.threads; })
        .def_property_readonly("mrays_per_second", [](const PyFrame& f) { return f.stats.mrays_per_second(); });

    py::class_<PyRenderer>(m, "Renderer", "Renders frame after frame of one Tree, keeping its Embree scene and threads between calls.")
        .def(py::init([](const AnyOctree& tree, const py::object& iso, const py::object& size, int threads, bool depth, bool normal,
                         const std::string& root_finder, int iterations, double lod) {
                 const std::vector<double> real = isovalues_of(iso);
                 const RenderOptions o = options_of(tree, real, threads, depth, normal, root_finder, iterations, lod);
                 const std::array<int, 2> wh = size_of(size);
                 py::gil_scoped_release release;
                 return std::make_unique<PyRenderer>(PyRenderer{tree, tree.make_renderer(o), wh, real});
             }),
             py::arg("tree"), py::arg("iso"), py::arg("size") = py::make_tuple(512, 512), py::arg("threads") = 0,
             py::arg("depth") = false, py::arg("normal") = false, py::arg("root_finder") = "neubauer", py::arg("iterations") = -1,
             py::arg("lod") = 0.0)
        .def_property("iso", [](const PyRenderer& r) { return r.iso; },
                      [](PyRenderer& r, const py::object& iso) {
                          RenderOptions o = r.renderer.options();
                          const std::vector<double> real = isovalues_of(iso);
                          o.isovalues = stored_isovalues(r.tree, real);
                          r.renderer.set_options(o);
                          r.iso = real;
                      }, "the isovalues in real values (stored * slope + inter of Tree.info()['value_scale']); setting them keeps the scene")
        .def("render", [](const PyRenderer& r, const std::optional<Camera>& camera) {
            const Camera c = camera_for(r.tree, camera, r.size);
            Frame f;
            {
                py::gil_scoped_release release;
                r.renderer.render(c, f);
            }
            return to_python(std::move(f));
        }, py::arg("camera") = py::none(), "One frame of the renderer's size (the tree's default framing without a camera). The GIL is released.");

}

void add_tree_render(py::class_<AnyOctree>& tree_class) {
    tree_class.def(
        "render",
        [](const AnyOctree& tree, const py::object& iso, const std::optional<Camera>& camera, const py::object& size, int threads,
           bool depth, bool normal, const std::string& root_finder, double lod) {
            const RenderOptions o = options_of(tree, isovalues_of(iso), threads, depth, normal, root_finder, -1, lod);
            const Camera c = camera_for(tree, camera, size_of(size));
            Frame f;
            {
                py::gil_scoped_release release;
                f = tree.render(c, o);
            }
            return to_python(std::move(f));
        },
        py::arg("iso"), py::arg("camera") = py::none(), py::arg("size") = py::make_tuple(512, 512), py::arg("threads") = 0,
        py::arg("depth") = false, py::arg("normal") = false, py::arg("root_finder") = "neubauer", py::arg("lod") = 0.0,
        R"(Renders the isosurface(s) `iso` (a number or up to 8, real values: the tree's value_scale applied,
as octiso-render --iso) into a Frame of `size` (width, height):
with `camera`, or the default three-quarter framing. depth/normal add those outputs. lod = F > 0 is
octiso-render --lod F (level of detail: cells up to F pixels wide; 0, the default, is exact).
The GIL is released.)");
}

}  // namespace octiso::python
