// libFuzzer target: read_raw (dims, type, endianness and offset from the first 16 bytes, the rest
// the file) and a full read of every voxel through the typed view.
#include <cstring>

#include "fuzz/fuzz_util.h"
#include "octiso/error.h"
#include "octiso/reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 16) return 0;
    uint16_t d[3];
    std::memcpy(d, data, sizeof d);
    const octiso::ScalarType type = octiso::ScalarType(data[6] % octiso::kScalarTypeCount);
    const octiso::Endian endian = (data[7] & 1) ? octiso::Endian::big : octiso::Endian::little;
    uint64_t offset = 0;
    std::memcpy(&offset, data + 8, sizeof offset);
    offset %= 64 + (data[7] & 0x80 ? UINT64_MAX / 2 : 0);   // mostly small, sometimes absurd
    octiso::fuzz::MemFile f(data + 16, size - 16, "raw");
    if (!f.ok()) return 0;
    try {
        const octiso::LoadedVolume v = octiso::read_raw(f.path(), octiso::Dims{d[0], d[1], d[2]}, type, endian, offset);
        double sum = 0;
        octiso::dispatch_scalar_type(v.type(), [&](auto tag) {
            using T = decltype(tag);
            const octiso::VolumeView<T> view = v.view<T>();
            for (uint64_t i = 0; i < v.dims().voxels(); ++i) sum += double(view.load(i));
        });
        volatile double sink = sum;
        (void)sink;
    } catch (const octiso::Error&) {
    }
    return 0;
}
