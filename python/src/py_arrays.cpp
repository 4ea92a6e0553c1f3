// numpy <-> octiso: dtypes, zero-copy views of input arrays, and output arrays that adopt the
// renderer's vectors (a capsule frees the vector when the array dies).
#include <bit>
#include <string>

#include "bindings.h"

namespace octiso::python {

ScalarType scalar_type_of_dtype(const py::dtype& dtype) {
    const char kind = dtype.kind();
    const py::ssize_t size = dtype.itemsize();
    if (kind == 'u' && size == 1) return ScalarType::u8;
    if (kind == 'i' && size == 1) return ScalarType::i8;
    if (kind == 'u' && size == 2) return ScalarType::u16;
    if (kind == 'i' && size == 2) return ScalarType::i16;
    if (kind == 'u' && size == 4) return ScalarType::u32;
    if (kind == 'i' && size == 4) return ScalarType::i32;
    if (kind == 'f' && size == 4) return ScalarType::f32;
    if (kind == 'f' && size == 8) return ScalarType::f64;
    throw py::type_error("octiso stores uint8, int8, uint16, int16, uint32, int32, float32 or float64 voxels, not " +
                         py::repr(dtype).cast<std::string>());
}

py::dtype dtype_of(ScalarType type) {
    return dispatch_scalar_type(type, [](auto tag) { return py::dtype::of<decltype(tag)>(); });
}

ArrayVolume volume_of_array(const py::array& array) {
    if (array.ndim() != 3)
        throw py::value_error("expected a 3-D array indexed [z, y, x], found " + std::to_string(array.ndim()) + " dimensions");
    if (!(array.flags() & py::array::c_style))
        throw py::value_error("expected a C-contiguous array (x fastest, as raw files); pass numpy.ascontiguousarray(a)");
    const ScalarType type = scalar_type_of_dtype(array.dtype());
    for (int a = 0; a < 3; ++a)
        if (array.shape(a) < 1 || array.shape(a) > (py::ssize_t(1) << 30))
            throw py::value_error("every extent must lie in 1..2^30, found shape (" + std::to_string(array.shape(0)) + ", " +
                                  std::to_string(array.shape(1)) + ", " + std::to_string(array.shape(2)) + ")");
    // '=' and '|' are native; '<' or '>' only when it differs from this machine's order.
    const char order = array.dtype().byteorder();
    const bool swap = (order == '>' && std::endian::native == std::endian::little) ||
                      (order == '<' && std::endian::native == std::endian::big);
    const Dims dims{uint32_t(array.shape(2)), uint32_t(array.shape(1)), uint32_t(array.shape(0))};
    return {type, dims, static_cast<const std::byte*>(array.data()), swap};
}

template <typename T> py::array_t<T> array_owning(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
    auto* owned = new std::vector<T>(std::move(values));
    py::capsule free_when_done(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
    return py::array_t<T>(shape, owned->data(), free_when_done);
}
template py::array_t<uint8_t> array_owning(std::vector<uint8_t>&&, std::vector<py::ssize_t>);
template py::array_t<float> array_owning(std::vector<float>&&, std::vector<py::ssize_t>);

std::array<double, 3> vec3_of(const py::object& value, const char* what) {
    std::array<double, 3> v{};
    try {
        const py::sequence s = value.cast<py::sequence>();
        if (py::len(s) != 3) throw py::value_error("");
        for (size_t a = 0; a < 3; ++a) v[a] = s[a].cast<double>();
    } catch (const py::error_already_set&) {
        throw py::value_error(std::string(what) + ": expected three numbers (x, y, z)");
    } catch (const py::cast_error&) {
        throw py::value_error(std::string(what) + ": expected three numbers (x, y, z)");
    } catch (const py::value_error&) {
        throw py::value_error(std::string(what) + ": expected three numbers (x, y, z)");
    }
    return v;
}

}  // namespace octiso::python
