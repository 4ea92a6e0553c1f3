// libFuzzer target: whatever .oct loads (after re-checksumming) is rendered at 12x12 with an
// isovalue taken from the input, colour, depth and normals, through the Embree path and the
// direct one, at full resolution or with a level of detail (byte 8, bits 1-3: --lod 0 .. 64),
// the file validated whole or block by block as the rays read it (bit 4: Verify::Touched; then a
// defect the frame read must be reported by check_unchanged(), and the frame stay in the file).
// Every pixel must come out finite (depth: finite or +inf), the normals unit or 0.
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "fuzz/fuzz_util.h"
#include "octiso/camera.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/render.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 9) return 0;
    double iso;
    std::memcpy(&iso, data, sizeof iso);
    const bool embree = data[8] & 1;
    constexpr double kLod[8] = {0, 0.5, 1, 2, 4, 8, 16, 64};
    const double lod = kLod[(data[8] >> 1) & 7];
    const octiso::Verify verify = (data[8] >> 4) & 1 ? octiso::Verify::Touched : octiso::Verify::Full;
    std::vector<uint8_t> bytes(data + 9, data + size);
    octiso::fuzz::rechecksum(bytes);
    octiso::fuzz::MemFile f(bytes.data(), bytes.size(), "render");
    if (!f.ok() || !std::isfinite(iso)) return 0;
    try {
        const octiso::OctFile file = octiso::OctFile::open(f.path(), verify);
        const octiso::OctInfo& info = file.info();
        octiso::RenderOptions options;
        options.isovalues = {iso};
        options.want_depth = options.want_normal = true;
        options.use_embree = embree;
        options.lod = lod;
        options.threads = 1;
        const octiso::RenderLimits limits{info.iso_range, f.path()};
        octiso::validate_options(options, limits);
        const octiso::Camera camera = octiso::frame_data_box(info.dims, info.placement, 12, 12);
        octiso::Frame frame;
        octiso::dispatch_scalar_type(info.type, [&](auto tag) {
            using T = decltype(tag);
            octiso::Renderer(file.step<T>(0), info.placement, options, limits).render(camera, frame);
        });
        file.check_unchanged();   // Touched: a bad node read above is refused here
        for (float t : frame.depth)
            if (std::isnan(t)) std::abort();
        for (size_t p = 0; p + 2 < frame.normal.size(); p += 3) {
            const float* n = &frame.normal[p];
            if (!std::isfinite(n[0]) || !std::isfinite(n[1]) || !std::isfinite(n[2])) std::abort();
            const float len2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
            if (len2 != 0 && std::fabs(len2 - 1) > 1e-3f) std::abort();
        }
    } catch (const octiso::Error&) {
    }
    return 0;
}
