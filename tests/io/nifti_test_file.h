// Small NIfTI-1 files with a chosen header for the reader tests (nifti_stream_test.cpp,
// nifti_placement_test.cpp): every field the readers use is set by name, written byte by byte at
// the offsets of the NIfTI-1 standard (nifti1.h), so the tests do not share the readers' parser.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <zlib.h>

namespace octiso::test {

/// A NIfTI-1 single file: header, 4 extension bytes, the data at 352. `big` writes every header
/// number big-endian (the caller passes big-endian data then).
struct Nifti1 {
    int16_t dim[8] = {3, 1, 1, 1, 1, 1, 1, 1};
    int16_t datatype = 4, bitpix = 16;
    float pixdim[8] = {1, 1, 1, 1, 1, 1, 1, 1};   ///< pixdim[0] is qfac
    float slope = 1, inter = 0;
    int16_t qform_code = 0, sform_code = 0;
    float quatern[3] = {};   ///< b, c, d
    float qoffset[3] = {};
    float srow[12] = {};
    bool big = false;

    std::string bytes(const std::string& data) const {
        std::string h(352, '\0');
        auto put = [&](size_t at, auto v) {
            unsigned char b[sizeof v];
            std::memcpy(b, &v, sizeof v);
            if (big) std::reverse(b, b + sizeof v);
            std::memcpy(&h[at], b, sizeof v);
        };
        put(0, int32_t(348));
        for (int i = 0; i < 8; ++i) put(40 + 2 * size_t(i), dim[i]);
        put(70, datatype);
        put(72, bitpix);
        for (int i = 0; i < 8; ++i) put(76 + 4 * size_t(i), pixdim[i]);
        put(108, 352.0f);
        put(112, slope);
        put(116, inter);
        put(252, qform_code);
        put(254, sform_code);
        for (int i = 0; i < 3; ++i) put(256 + 4 * size_t(i), quatern[i]);
        for (int i = 0; i < 3; ++i) put(268 + 4 * size_t(i), qoffset[i]);
        for (int i = 0; i < 12; ++i) put(280 + 4 * size_t(i), srow[i]);
        std::memcpy(&h[344], "n+1\0", 4);
        return h + data;
    }
    void set_srow(const float (&m)[12]) {
        sform_code = 1;
        std::memcpy(srow, m, sizeof srow);
    }
};

inline void write_file(const std::string& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

inline void write_gz(const std::string& path, const std::string& bytes) {
    gzFile f = ::gzopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(::gzwrite(f, bytes.data(), unsigned(bytes.size())), int(bytes.size()));
    ::gzclose(f);
}

}  // namespace octiso::test
