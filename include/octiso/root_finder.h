// The root finders a render can use (Knoll et al. 2006, Sec. 4.4; notes/rootfinding.md), by
// name. The policies themselves are src/render/roots.h; this is the one enum for all layers.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace octiso {

enum class RootFinder { neubauer, schwarze, linear, exact };

/// "neubauer", "schwarze", "linear", "exact"; nullopt for anything else.
std::optional<RootFinder> parse_root_finder(std::string_view name);
/// The same, throwing Error("--root-finder", ...) for an unknown name.
RootFinder parse_root_finder_name(const std::string& name);
const char* root_finder_name(RootFinder finder);

}  // namespace octiso
