// parse_nifti_header() (nifti_header.h). Field offsets, NIfTI-1 (348 bytes) / NIfTI-2 (540):
//   dim           40 int16[8]  | 16 int64[8]        pixdim       76 float[8] | 104 double[8]
//   datatype      70 int16     | 12 int16           vox_offset  108 float    | 168 int64
//   scl_slope    112 float     | 176 double         scl_inter   116 float    | 184 double
//   qform_code   252 int16     | 344 int32          sform_code  254 int16    | 348 int32
//   quatern_b,c,d 256 float[3] | 352 double[3]      qoffset_x,y,z 268 float[3] | 376 double[3]
//   srow_x,y,z   280 float[12] | 400 double[12]
#include "io/nifti_header.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <zlib.h>

#include "io/header_check.h"
#include "octiso/error.h"

namespace octiso::io {

namespace {

template <typename V> V load(const unsigned char* p, bool swap) {
    unsigned char b[sizeof(V)];
    std::memcpy(b, p, sizeof b);
    if (swap) std::reverse(b, b + sizeof b);
    V v;
    std::memcpy(&v, b, sizeof v);
    return v;
}

ScalarType type_of(int datatype) {
    switch (datatype) {
        case 2: return ScalarType::u8;
        case 256: return ScalarType::i8;
        case 4: return ScalarType::i16;
        case 512: return ScalarType::u16;
        case 8: return ScalarType::i32;
        case 768: return ScalarType::u32;
        case 16: return ScalarType::f32;
        default: return ScalarType::f64;   // 64: check_nifti_header() admits nothing else
    }
}

std::string g17(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.17g", v);
    return b;
}

}  // namespace

NiftiHeader parse_nifti_header(const unsigned char* h, size_t n, const std::string& path) {
    NiftiHeader out;
    // 1. Version and byte order, as check_nifti_header() decided them.
    const int32_t raw = load<int32_t>(h, false);
    out.swap = raw != 348 && raw != 540;
    const bool v2 = (out.swap ? load<int32_t>(h, true) : raw) == 540;
    if (n < (v2 ? 540u : 348u)) throw Error(path, "NIfTI header is truncated");
    out.header_bytes = v2 ? 540 : 348;
    const bool s = out.swap;
    auto f = [&](size_t off1, size_t off2) { return v2 ? load<double>(h + off2, s) : double(load<float>(h + off1, s)); };

    // 2. Dimensions: x, y, z, then time; anything beyond must be 1.
    int64_t dim[8];
    for (int i = 0; i < 8; ++i) dim[i] = v2 ? load<int64_t>(h + 16 + 8 * i, s) : load<int16_t>(h + 40 + 2 * i, s);
    uint64_t ext[4] = {1, 1, 1, 1};
    for (int i = 1; i <= dim[0] && i <= 7; ++i) {
        if (i > 4 && dim[i] != 1)
            throw Error(path, "NIfTI dim[" + std::to_string(i) + "] is " + std::to_string(dim[i]) +
                                  " (octiso reads 3-D volumes and 4-D time series)");
        if (i <= 4) ext[i - 1] = uint64_t(dim[i]);
    }
    for (int a = 0; a < 3; ++a)
        if (ext[a] > Dims::kMaxExtent)
            throw Error(path, "NIfTI dim[" + std::to_string(a + 1) + "] exceeds the largest extent " + std::to_string(Dims::kMaxExtent));
    if (ext[3] > UINT32_MAX) throw Error(path, "NIfTI has more than 2^32-1 time steps");
    out.dims = Dims{uint32_t(ext[0]), uint32_t(ext[1]), uint32_t(ext[2])};
    out.time_steps = uint32_t(ext[3]);
    out.type = type_of(v2 ? load<int16_t>(h + 12, s) : load<int16_t>(h + 70, s));
    out.vox_offset = v2 ? uint64_t(load<int64_t>(h + 168, s)) : uint64_t(load<float>(h + 108, s));
    out.scl_slope = f(112, 176);
    out.scl_inter = f(116, 184);

    // 3. Value scaling as nibabel's get_slope_inter(): a zero or non-finite slope means none.
    if (out.scl_slope != 0 && std::isfinite(out.scl_slope)) {
        if (!std::isfinite(out.scl_inter))
            throw Error(path, "NIfTI scl_slope is " + g17(out.scl_slope) + " but scl_inter is not finite");
        out.value_scale = ValueScale{out.scl_slope, out.scl_inter};
    }

    // 4. The affine, world = A * (i, j, k, 1), as nibabel's get_best_affine() builds it.
    const int qform_code = v2 ? load<int32_t>(h + 344, s) : load<int16_t>(h + 252, s);
    const int sform_code = v2 ? load<int32_t>(h + 348, s) : load<int16_t>(h + 254, s);
    double pixdim[4];
    for (int i = 0; i < 4; ++i) pixdim[i] = v2 ? load<double>(h + 104 + 8 * i, s) : double(load<float>(h + 76 + 4 * i, s));
    out.qfac = pixdim[0] < 0 ? -1 : 1;
    double A[3][4] = {};
    const char* source = nullptr;
    if (sform_code > 0) {
        source = "sform";
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) A[r][c] = f(280 + 16 * size_t(r) + 4 * size_t(c), 400 + 32 * size_t(r) + 8 * size_t(c));
    } else if (qform_code > 0) {
        source = "qform";
        const double b = f(256, 352), c = f(260, 360), d = f(264, 368);
        // nibabel's fillpositive: a = sqrt(1 - b^2 - c^2 - d^2), 0 when rounding makes it negative.
        const double a = std::sqrt(std::max(0.0, 1.0 - (b * b + c * c + d * d)));
        const double R[3][3] = {{a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
                                {2 * (b * c + a * d), a * a + c * c - b * b - d * d, 2 * (c * d - a * b)},
                                {2 * (b * d - a * c), 2 * (c * d + a * b), a * a + d * d - c * c - b * b}};
        const double zoom[3] = {std::abs(pixdim[1]), std::abs(pixdim[2]), std::abs(pixdim[3]) * out.qfac};
        for (int r = 0; r < 3; ++r) {
            for (int col = 0; col < 3; ++col) A[r][col] = R[r][col] * zoom[col];
            A[r][3] = f(268 + 4 * size_t(r), 376 + 8 * size_t(r));
        }
    }

    // 5. Placement (CONVENTIONS 2b). Without either code: |pixdim| spacing, origin 0.
    //    Deviation from nibabel, whose fallback centres the grid (Analyze): CONVENTIONS 2b chose origin 0.
    const uint64_t extent[3] = {ext[0], ext[1], ext[2]};
    bool diagonal = source != nullptr;
    for (int r = 0; r < 3 && diagonal; ++r) {
        // A quaternion of a 90 or 180 degree turn leaves rounding dust off the diagonal: ignore
        // entries below 1e-6 of their column's diagonal (a millionth of a voxel at the far side).
        const double tiny = 1e-6 * std::abs(A[r][r]);
        if (!(std::abs(A[r][r]) > 0) || !std::isfinite(A[r][r])) diagonal = false;
        for (int c = 0; c < 3; ++c)
            if (c != r && !(std::abs(A[c][r]) <= tiny)) diagonal = false;
    }
    if (diagonal) {
        for (int a = 0; a < 3; ++a) {
            const double step = A[a][a];
            out.placement.spacing[size_t(a)] = std::abs(step);
            // Reversed: tree index i' = n-1-i, so world = A[a][3] + step*(n-1) + |step|*i'.
            out.placement.origin[size_t(a)] = step < 0 ? A[a][3] + step * double(extent[a] - 1) : A[a][3];
            if (step < 0) out.flipped_axes |= uint8_t(1u << a);
        }
    } else {
        // As vtkNIFTIImageReader places it: pixdim spacing, origin 0, slices reversed for qfac -1
        // (which makes its qform matrix a rotation); the rotation itself is not applied.
        for (int a = 0; a < 3; ++a) out.placement.spacing[size_t(a)] = std::abs(pixdim[a + 1]);
        if (out.qfac < 0) out.flipped_axes = 4;
        if (source)
            out.warning = std::string("NIfTI ") + source + " is oblique (rotated, sheared or with permuted axes): placed as "
                          "VTK does (pixdim spacing, origin 0, the rotation ignored)";
    }
    return out;
}

NiftiHeader read_nifti_header(const std::string& path) {
    check_declared_size(path, VolumeFormat::nifti);
    unsigned char h[540] = {};
    gzFile f = ::gzopen(path.c_str(), "rb");
    if (!f) throw Error(path, "cannot open as NIfTI");
    const int r = ::gzread(f, h, sizeof h);
    ::gzclose(f);
    if (r < 0) throw Error(path, "not a readable gzip stream");
    return parse_nifti_header(h, size_t(r), path);
}

}  // namespace octiso::io
