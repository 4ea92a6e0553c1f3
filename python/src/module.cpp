// The `octiso` Python module: numpy in, images out. octiso.Error crosses the boundary as the
// tools' one-line message: ValueError when the subject is a flag or an argument, OSError when
// it names a file (CONVENTIONS 3 messages are "SUBJECT: PROBLEM").
#include <string>

#include "bindings.h"
#include "octiso/error.h"
#include "octiso/version.h"

namespace octiso::python {
namespace {

bool names_a_file(const Error& e) {
    const std::string& s = e.subject();
    // Flags ("--iso", "-o") and the library's argument names ("tile_size", "render_tiles") are
    // not files; everything else the library names is the path it read or wrote.
    if (s.empty() || s[0] == '-') return false;
    return s.find('/') != std::string::npos || s.find('.') != std::string::npos;
}

}  // namespace
}  // namespace octiso::python

PYBIND11_MODULE(_octiso, m) {
    using namespace octiso::python;
    m.doc() = "octiso: exact isosurfaces of losslessly compressed octree volumes, ray traced on all cores.";
    m.attr("__version__") = OCTISO_VERSION_STRING;
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const octiso::Error& e) {
            PyErr_SetString(names_a_file(e) ? PyExc_OSError : PyExc_ValueError, e.what());
        }
    });
    bind_tree(m);
    bind_render(m);
    bind_convert(m);
}
