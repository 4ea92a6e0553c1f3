// Root finders by name (--root-finder and the benchmarks); the names are the policies' own.
#include "octiso/root_finder.h"

#include "octiso/error.h"
#include "render/roots.h"

namespace octiso {

std::optional<RootFinder> parse_root_finder(std::string_view name) {
    if (name == Neubauer::name) return RootFinder::neubauer;
    if (name == Schwarze::name) return RootFinder::schwarze;
    if (name == Linear::name) return RootFinder::linear;
    if (name == Exact::name) return RootFinder::exact;
    return std::nullopt;
}

RootFinder parse_root_finder_name(const std::string& name) {
    const auto finder = parse_root_finder(name);
    if (!finder) throw Error("--root-finder", "expected neubauer, schwarze, linear or exact, found '" + name + "'");
    return *finder;
}

const char* root_finder_name(RootFinder finder) {
    switch (finder) {
        case RootFinder::neubauer: return Neubauer::name;
        case RootFinder::schwarze: return Schwarze::name;
        case RootFinder::linear: return Linear::name;
        case RootFinder::exact: break;
    }
    return Exact::name;
}

}  // namespace octiso
