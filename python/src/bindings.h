// What the binding files of the `octiso` Python module share: the groups they add to the module
// (module.cpp calls them in order) and the numpy <-> octiso conversions (py_arrays.cpp).
// Every function that builds, renders, decodes or writes releases the GIL while it works.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <cstdint>
#include <vector>

#include "octiso/volume.h"

namespace octiso {
class AnyOctree;
}

namespace octiso::python {

namespace py = pybind11;

void bind_tree(py::module_& m);     // build, open, convert, Tree, File (py_tree.cpp)
void bind_render(py::module_& m);   // Camera, Frame, Renderer (py_render.cpp)
void bind_convert(py::module_& m);  // convert (py_convert.cpp)
void add_tree_render(py::class_<AnyOctree>& tree_class);   // Tree.render (py_render.cpp)

/// The scalar type of a numpy dtype; TypeError for any dtype octiso does not store.
ScalarType scalar_type_of_dtype(const py::dtype& dtype);
/// The numpy dtype (native byte order) of a scalar type.
py::dtype dtype_of(ScalarType type);

/// A C-contiguous 3-D array indexed [z, y, x] seen as octiso's x-fastest volume, without copying:
/// `data` points into the array's buffer, which the caller keeps alive while it is used.
/// ValueError for another rank, a non-contiguous array or an empty extent; TypeError for a dtype
/// octiso does not store. A non-native byte order is read with swapping.
struct ArrayVolume {
    ScalarType type;
    Dims dims;
    const std::byte* data;
    bool swap_bytes;
};
ArrayVolume volume_of_array(const py::array& array);

/// A numpy array that takes over `values` (no copy): its buffer is the vector's, freed with it.
template <typename T> py::array_t<T> array_owning(std::vector<T>&& values, std::vector<py::ssize_t> shape);

/// (x, y, z) from a Python 3-sequence, naming `what` in the ValueError.
std::array<double, 3> vec3_of(const py::object& value, const char* what);

}  // namespace octiso::python
