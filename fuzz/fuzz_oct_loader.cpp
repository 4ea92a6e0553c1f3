// libFuzzer target: the .oct loader and validator (header, table, every step's indices), then
// verify_octree on whatever loads. Any Error is a correct refusal; a crash, hang or sanitizer
// report is a finding.
#include "fuzz/fuzz_util.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/verify.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::vector<uint8_t> bytes(data, data + size);
    octiso::fuzz::rechecksum(bytes);
    octiso::fuzz::MemFile f(bytes.data(), bytes.size(), "oct");
    if (!f.ok()) return 0;
    try {
        const octiso::OctFile file = octiso::OctFile::open(f.path());
        const octiso::OctInfo& info = file.info();
        if (info.dims.voxels() > (1u << 20)) return 0;   // verify decodes a dense step: keep it small
        for (uint32_t k = 0; k < info.step_count && k < 8; ++k) (void)file.step_sizes(k);
        (void)octiso::verify_octree(file);
    } catch (const octiso::Error&) {
    }
    return 0;
}
