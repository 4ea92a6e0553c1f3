// octiso.build / open / convert and the Tree and File classes: a Tree is an AnyOctree (any of
// the 8 scalar types, built from a numpy array or a step of a mapped .oct file), a File the
// mapped series it came from. The voxels of an input array are read in place, never copied.
#include <pybind11/stl.h>


#include <memory>
#include <optional>
#include <string>

#include "bindings.h"
#include "util/shared_arena.h"
#include "octiso/any_octree.h"
#include "octiso/build.h"
#include "octiso/oct_file.h"

namespace octiso::python {
namespace {

/// Runs f in the process's arena of `threads` threads (0: all cores; util/shared_arena.h, the
/// one the Renderer and the builder use too), without the GIL.
template <class F> auto without_gil(int threads, F&& f) {
    py::gil_scoped_release release;
    return in_shared_arena(threads, f);
}

AnyOctree build_from_array(const py::array& array, const py::object& spacing, const py::object& origin,
                           const std::optional<std::array<double, 2>>& iso_range, double tolerance, int threads) {
    if (threads < 0) throw py::value_error("threads: must be >= 0 (0: all cores)");
    if (!(tolerance >= 0)) throw py::value_error("tolerance: must be >= 0");
    if (iso_range && !((*iso_range)[0] < (*iso_range)[1])) throw py::value_error("iso_range: expected (lo, hi) with lo < hi");
    const ArrayVolume volume = volume_of_array(array);
    Placement placement;
    placement.spacing = vec3_of(spacing, "spacing");
    placement.origin = vec3_of(origin, "origin");
    for (double s : placement.spacing)
        if (!(s > 0) || !std::isfinite(s)) throw py::value_error("spacing: expected three positive numbers");
    BuildOptions options;
    options.iso_range = iso_range;
    options.tolerance = tolerance;
    options.threads = threads;
    options.source_name = "array";
    return dispatch_scalar_type(volume.type, [&](auto tag) {
        using T = decltype(tag);
        const VolumeView<T> view{volume.data, volume.dims, volume.swap_bytes};
        return without_gil(threads, [&] { return AnyOctree::build(view, placement, options); });
    });
}

py::dict info_dict(const AnyOctree& tree) {
    const AnyOctreeInfo info = tree.info();
    py::dict d;
    d["type"] = scalar_type_name(info.type);
    d["dims"] = py::make_tuple(info.dims.x, info.dims.y, info.dims.z);
    d["shape"] = py::make_tuple(info.dims.z, info.dims.y, info.dims.x);
    d["spacing"] = py::make_tuple(info.placement.spacing[0], info.placement.spacing[1], info.placement.spacing[2]);
    d["origin"] = py::make_tuple(info.placement.origin[0], info.placement.origin[1], info.placement.origin[2]);
    d["dmax"] = info.dmax;
    // Stored-to-real values (a NIfTI's scl_slope/scl_inter): real = stored * slope + inter. The
    // ranges are real values, as the tools report them and as render() takes isovalues
    // (CONVENTIONS 2b); the tolerance stays in stored units, as the C++ API records it.
    const ValueScale& scale = info.value_scale;
    const auto real = [&](const std::optional<std::array<double, 2>>& stored) {
        if (!stored) return py::object(py::none());
        const std::array<double, 2> r = scale.real_range(*stored);
        return py::object(py::make_tuple(r[0], r[1]));
    };
    d["value_range"] = real(info.value_range);
    d["iso_range"] = real(info.iso_range);
    d["tolerance"] = info.tolerance;
    d["value_scale"] = py::make_tuple(scale.slope, scale.inter);
    d["flipped_axes"] = int(info.flipped_axes);
    d["interior_bytes"] = info.sizes.interior_bytes;
    d["minmax_bytes"] = info.sizes.minmax_bytes;
    d["cap_bytes"] = info.sizes.cap_bytes;
    d["bytes"] = info.sizes.interior_bytes + info.sizes.cap_bytes;
    d["dense_bytes"] = info.dense_bytes;
    d["nodes_per_depth"] = info.sizes.nodes_per_depth;
    d["scalar_leaves_per_depth"] = info.sizes.scalar_leaves_per_depth;
    d["source"] = info.source;
    return d;
}

py::array to_numpy(const AnyOctree& tree) {
    const Dims d = tree.dims();
    py::array out(dtype_of(tree.type()), std::vector<py::ssize_t>{py::ssize_t(d.z), py::ssize_t(d.y), py::ssize_t(d.x)});
    auto* bytes = static_cast<std::byte*>(out.mutable_data());
    const uint64_t n = tree.dense_bytes();
    {
        py::gil_scoped_release release;
        tree.decode(std::span<std::byte>(bytes, n));
    }
    return out;
}

}  // namespace

void bind_tree(py::module_& m) {
    py::class_<AnyOctree> tree_class(m, "Tree", R"(An octree volume of one scalar type: built from an array (octiso.build) or a
step of a .oct file (octiso.open(...).step(k)). Immutable; copies share the same data.)");
    tree_class.def_property_readonly("dtype", [](const AnyOctree& t) { return dtype_of(t.type()); },
                               "numpy dtype of the stored voxels")
        .def_property_readonly("shape", [](const AnyOctree& t) {
            const Dims d = t.dims();
            return py::make_tuple(d.z, d.y, d.x);
        }, "(nz, ny, nx): the shape of to_numpy()")
        .def_property_readonly("dims", [](const AnyOctree& t) {
            const Dims d = t.dims();
            return py::make_tuple(d.x, d.y, d.z);
        }, "(nx, ny, nz), x fastest")
        .def_property_readonly("spacing", [](const AnyOctree& t) {
            const auto& s = t.placement().spacing;
            return py::make_tuple(s[0], s[1], s[2]);
        }, "world size of a voxel step per axis (x, y, z)")
        .def_property_readonly("origin", [](const AnyOctree& t) {
            const auto& o = t.placement().origin;
            return py::make_tuple(o[0], o[1], o[2]);
        }, "world position of voxel (0, 0, 0)")
        .def("info", &info_dict, "A dict: type, dims, shape, spacing, origin, dmax, value_range, iso_range, tolerance, value_scale (slope, inter: real = stored * slope + inter; value_range and iso_range are real values, tolerance stored), flipped_axes, byte counts, nodes and scalar leaves per depth, source.")
        .def("to_numpy", &to_numpy, "The voxels back as a new array of shape (nz, ny, nx), exactly as built (lossless trees).")
        .def("save", [](const AnyOctree& t, const std::string& path) {
            py::gil_scoped_release release;
            t.save(path);
        }, py::arg("path"), "Writes a one-step .oct file (a temporary renamed on success: never a partial file).")
        .def("__repr__", [](const AnyOctree& t) {
            const Dims d = t.dims();
            return "<octiso.Tree " + std::string(scalar_type_name(t.type())) + " " + std::to_string(d.x) + "x" +
                   std::to_string(d.y) + "x" + std::to_string(d.z) + ">";
        });
    add_tree_render(tree_class);

    py::class_<OctFile, std::shared_ptr<OctFile>>(m, "File", "A mapped .oct file (zero copy): one or more time steps of one octree each.")
        .def_property_readonly("path", &OctFile::path)
        .def_property_readonly("steps", [](const OctFile& f) { return f.info().step_count; }, "number of time steps")
        .def("__len__", [](const OctFile& f) { return f.info().step_count; })
        .def("step", [](const std::shared_ptr<OctFile>& f, uint32_t k) {
            py::gil_scoped_release release;   // the first use of a step validates it
            return AnyOctree::step(f, k);
        }, py::arg("k") = 0, "Step k as a Tree; validated completely on first use.")
        .def("info", [](const std::shared_ptr<OctFile>& f) {
            py::gil_scoped_release release;
            const AnyOctree t = AnyOctree::step(f, 0);
            py::gil_scoped_acquire acquire;
            py::dict d = info_dict(t);
            d["steps"] = f->info().step_count;
            d["file_bytes"] = f->file_bytes();
            return d;
        }, "The header and the sizes of step 0, as Tree.info(), plus steps and file_bytes.")
        .def("__repr__", [](const OctFile& f) { return "<octiso.File '" + f.path() + "' " + std::to_string(f.info().step_count) + " step(s)>"; });

    m.def("build", &build_from_array, py::arg("array"), py::arg("spacing") = py::make_tuple(1.0, 1.0, 1.0),
          py::arg("origin") = py::make_tuple(0.0, 0.0, 0.0), py::arg("iso_range") = py::none(), py::arg("tolerance") = 0.0,
          py::arg("threads") = 0,
          R"(Builds a Tree from a C-contiguous 3-D array indexed [z, y, x] (x fastest, as raw files) of
uint8, int8, uint16, int16, uint32, int32, float32 or float64, reading the voxels in place (no copy).
iso_range=(lo, hi) clamps data that no isosurface strictly inside (lo, hi) can see; tolerance > 0
merges siblings within that absolute error; threads=0 uses all cores. The GIL is released.)");

    m.def("open", [](const std::string& path) {
        py::gil_scoped_release release;
        return std::make_shared<OctFile>(OctFile::open(path));
    }, py::arg("path"), "Maps a .oct file and checks its header (steps are validated on first use).");
}

}  // namespace octiso::python
