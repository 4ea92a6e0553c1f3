// ConvertSource (include/octiso/convert.h): the five kinds of input octiso-convert accepts and
// how step i of each is named and opened. Reading itself is reader.h and synthetic.h; this file
// only chooses which of them to call and applies the placement overrides to generated steps.
#include <cstdint>
#include <utility>

#include "octiso/convert.h"
#include "octiso/error.h"
#include "octiso/step_pattern.h"

namespace octiso {

ConvertSource ConvertSource::file(std::string path, RawOptions raw) {
    ConvertSource s;
    s.name_ = std::move(path);
    s.raw_ = std::move(raw);
    return s;
}

ConvertSource ConvertSource::files(std::vector<std::string> paths, RawOptions raw) {
    if (paths.empty()) throw Error("INPUT", "missing input file or --synthetic (see --help)");
    ConvertSource s;
    s.name_ = paths[0];
    if (paths.size() > 1) s.list_ = std::move(paths);
    s.raw_ = std::move(raw);
    return s;
}

ConvertSource ConvertSource::pattern(std::string pattern, long long first, long long last, RawOptions raw) {
    if (first < 0 || last < first || last - first >= (long long)UINT32_MAX)   // the count must fit 32 bits
        throw Error("--steps", "expected A:B with 0 <= A <= B, found " + std::to_string(first) + ":" + std::to_string(last));
    format_step(pattern, first, "--steps");   // the pattern is checked before any I/O
    ConvertSource s;
    s.name_ = std::move(pattern);
    s.steps_ = std::array<long long, 2>{first, last};
    s.raw_ = std::move(raw);
    return s;
}

ConvertSource ConvertSource::synthetic(const std::string& spec, std::optional<ScalarType> type, RawOptions raw) {
    ConvertSource s;
    s.synthetic_ = parse_synthetic(spec);
    s.synthetic_type_ = type;
    s.name_ = spec;
    s.raw_ = std::move(raw);
    return s;
}

ConvertSource ConvertSource::sparse_spheres(uint32_t n) {
    ConvertSource s;
    s.sparse_n_ = n;
    s.name_ = "sparse-spheres:" + std::to_string(n);
    return s;
}

uint32_t ConvertSource::step_count() const {
    if (synthetic_) return synthetic_->steps;
    if (!list_.empty()) return uint32_t(list_.size());
    if (steps_) return uint32_t((*steps_)[1] - (*steps_)[0] + 1);
    return 1;
}

std::string ConvertSource::step_path(uint32_t i) const {
    if (!list_.empty()) return list_[i];
    return steps_ ? format_step(name_, (*steps_)[0] + i, "--steps") : name_;
}

LoadedVolume ConvertSource::load(uint32_t i) const {
    if (sparse_n_) throw Error(name_, "is built directly as an octree and has no dense volume", ErrorKind::Other);
    if (synthetic_) {
        LoadedVolume v = synthetic_step(synthetic_->name, synthetic_->dims, i, synthetic_type_);
        Placement p = v.placement();
        if (raw_.spacing) p.spacing = *raw_.spacing;
        if (raw_.origin) p.origin = *raw_.origin;
        v.set_placement(p);
        return v;
    }
    return open_volume(step_path(i), raw_);
}

}  // namespace octiso
