// The --dataset list of the render benchmarks (packets, lod): SPEC[,SPEC...], each FILE@ISO or
// NAME:N@ISO. A FILE without a directory part is looked up in --mri-dir; NAME:N is a synthetic
// field at N^3 and a FILE ending in .oct an octree file, both used as written.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "cli/common/cli.h"
#include "octiso/error.h"
#include "octiso/loaded_volume.h"
#include "octiso/reader.h"
#include "octiso/synthetic.h"

namespace octiso::bench {

struct DatasetSpec {
    std::string name;     ///< as written (the table's label)
    std::string source;   ///< the path or synthetic spec to open
    double iso = 0;
    bool is_synthetic = false, is_oct = false;
};

inline std::vector<DatasetSpec> parse_dataset_specs(const std::string& text, const std::string& mri_dir) {
    std::vector<DatasetSpec> out;
    size_t pos = 0;
    while (pos <= text.size()) {
        const size_t comma = std::min(text.find(',', pos), text.size());
        const std::string item = text.substr(pos, comma - pos);
        const size_t at = item.rfind('@');
        if (at == std::string::npos) throw Error("--dataset", "expected FILE@ISO or NAME:N@ISO, found '" + item + "'");
        DatasetSpec s;
        s.name = item.substr(0, at);
        s.iso = cli::parse_double(item.substr(at + 1), "--dataset");
        s.is_oct = s.name.size() > 4 && s.name.compare(s.name.size() - 4, 4, ".oct") == 0;
        s.is_synthetic = !s.is_oct && s.name.find(':') != std::string::npos;
        const bool has_dir = s.name.find('/') != std::string::npos;
        s.source = s.is_oct || s.is_synthetic || has_dir ? s.name : mri_dir + "/" + s.name;
        out.push_back(s);
        pos = comma + 1;
    }
    return out;
}

/// The dense volume of a spec (a synthetic field at N^3, N up to `max_side`, or the scan read
/// whole); empty for a .oct file, which is used as it is.
inline LoadedVolume open_dense(const DatasetSpec& s, uint32_t max_side = 4096) {
    if (s.is_oct) return {};
    if (s.is_synthetic) {
        const size_t colon = s.name.find(':');
        const uint32_t n = uint32_t(cli::parse_int(s.name.substr(colon + 1), "--dataset", 4, max_side));
        return synthetic_step(s.name.substr(0, colon), Dims{n, n, n}, 0);
    }
    return open_volume(s.source, RawOptions{});
}

}  // namespace octiso::bench
