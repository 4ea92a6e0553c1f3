// libFuzzer target: the NIfTI-1/-2 header check that runs before any reader (issue 18: VTK
// crashed on datatypes it does not handle), on the raw header bytes with a fuzzed size bound,
// then the parse of what it accepts (the affine, quaternion and scaling of nifti_header.cpp).
#include <cstring>

#include "io/header_check.h"
#include "io/nifti_header.h"
#include "octiso/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 9) return 0;
    uint64_t bound = 0;
    std::memcpy(&bound, data, sizeof bound);
    const bool exact = data[8] & 1;
    try {
        octiso::io::check_nifti_header(data + 9, size - 9, bound, exact, "fuzz.nii");
        const octiso::io::NiftiHeader h = octiso::io::parse_nifti_header(data + 9, size - 9, "fuzz.nii");
        octiso::check_placement(h.placement, h.dims, "fuzz.nii");
    } catch (const octiso::Error&) {
    }
    return 0;
}
