// octiso.convert: the library's conversion pipeline (octiso/convert.h) from Python, with the
// tool's options as keywords; returns the report as a dict. The GIL is released while it runs.
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "octiso/convert.h"

namespace octiso::python {
namespace {

py::dict report_dict(const ConvertReport& r) {
    py::dict d;
    d["input"] = r.input;
    d["output"] = r.output;
    d["type"] = scalar_type_name(r.type);
    d["dims"] = py::make_tuple(r.dims.x, r.dims.y, r.dims.z);
    d["steps"] = r.steps;
    d["input_bytes"] = r.input_bytes;
    d["file_bytes"] = r.file_bytes;
    d["ratio"] = r.ratio();
    d["build_seconds"] = r.build_seconds;
    d["total_seconds"] = r.total_seconds;
    d["mvoxels_per_second"] = r.mvoxels_per_second();
    d["threads"] = r.threads;
    return d;
}

ScalarType type_named(const std::string& name) {
    for (ScalarType t : {ScalarType::u8, ScalarType::i8, ScalarType::u16, ScalarType::i16, ScalarType::u32, ScalarType::i32,
                         ScalarType::f32, ScalarType::f64})
        if (name == scalar_type_name(t)) return t;
    // numpy names too: uint8, float32, ...
    return scalar_type_of_dtype(py::dtype(name));
}

}  // namespace

void bind_convert(py::module_& m) {
    m.def(
        "convert",
        [](const py::object& path_in, const std::string& path_out, std::optional<std::array<uint32_t, 3>> dims,
           std::optional<std::string> dtype, std::optional<std::string> endian, std::optional<uint64_t> offset,
           std::optional<std::array<double, 3>> spacing, std::optional<std::array<double, 3>> origin,
           std::optional<std::array<double, 2>> iso_range, double tolerance, std::optional<double> nan_as, int threads) {
            RawOptions raw;
            if (dims) raw.dims = Dims{(*dims)[0], (*dims)[1], (*dims)[2]};
            if (dtype) raw.type = type_named(*dtype);
            if (endian) {
                if (*endian != "little" && *endian != "big") throw py::value_error("endian: expected 'little' or 'big'");
                raw.endian = *endian == "little" ? Endian::little : Endian::big;
            }
            raw.offset = offset;
            raw.spacing = spacing;
            raw.origin = origin;
            if (threads < 0) throw py::value_error("threads: must be >= 0 (0: all cores)");
            BuildOptions options;
            options.iso_range = iso_range;
            options.tolerance = tolerance;
            options.nan_as = nan_as;
            options.threads = threads;
            const ConvertSource source = py::isinstance<py::str>(path_in)
                                             ? ConvertSource::file(path_in.cast<std::string>(), raw)
                                             : ConvertSource::files(path_in.cast<std::vector<std::string>>(), raw);
            ConvertReport report;
            {
                py::gil_scoped_release release;
                report = convert(source, path_out, options);
            }
            return report_dict(report);
        },
        py::arg("path_in"), py::arg("path_out"), py::kw_only(), py::arg("dims") = py::none(), py::arg("dtype") = py::none(),
        py::arg("endian") = py::none(), py::arg("offset") = py::none(), py::arg("spacing") = py::none(),
        py::arg("origin") = py::none(), py::arg("iso_range") = py::none(), py::arg("tolerance") = 0.0,
        py::arg("nan_as") = py::none(), py::arg("threads") = 0,
        R"(Converts a volume file (.nii .nii.gz .vti .vtk .mhd .mha .nrrd .nhdr, or raw with dims=(nx, ny, nz)
and dtype=) or a list of files (a time series, one step each) into the .oct file path_out, exactly as
octiso-convert does; returns its report as a dict (bytes, ratio, seconds). The GIL is released.)");
}

}  // namespace octiso::python
