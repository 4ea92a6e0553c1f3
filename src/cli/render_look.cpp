#include "cli/render_look.h"

#include <cstdio>

#include "octiso/error.h"

namespace octiso::cli {

const char* const kLookUsage =
    "Ray-traced look (default: all off; each reports its cost in the frame report and --json):\n"
    "  --shadows                 shadows of the key light: one occlusion ray per lit hit (kit shading)\n"
    "  --ao N                    ambient occlusion: N cosine-weighted rays per hit, 1..256 (default 0: off;\n"
    "                            kit shading; darkens the ambient and fill light in creases)\n"
    "  --ao-distance VOXELS      reach of an ambient-occlusion ray (default 10 voxels)\n"
    "  --opacity A               opacity in [0, 1] of the k-th isovalue, given once per isovalue in order\n"
    "                            (default 1); below 1 the surfaces behind show through (front to back)\n"
    "  --clip NX,NY,NZ,D         keep the half-space NX*x + NY*y + NZ*z <= D (world units) and cut the\n"
    "                            rest away, for every ray; repeatable (the kept part is the intersection)\n"
    "  --clip-cap                draw the cut faces: where a --clip plane cuts through the inside of a surface\n"
    "                            (value >= V), a flat face in the colour of the innermost such isovalue\n"
    "                            (default off: the cut is open, as a VTK/ParaView clip of the surface)\n";

void LookFlags::declare(FlagSpec& spec) {
    spec.values.insert(spec.values.end(), {"--ao", "--ao-distance"});
    spec.lists.insert(spec.lists.end(), {"--opacity", "--clip"});
    spec.switches.insert(spec.switches.end(), {"--shadows", "--clip-cap"});
}

LookFlags LookFlags::take(const Flags& args) {
    LookFlags f;
    f.look.shadows = args.flag("--shadows");
    if (const auto ao = args.value("--ao")) f.look.ao_samples = int(parse_int(*ao, "--ao", 0, kMaxAoSamples));
    if (const auto reach = args.value("--ao-distance")) {
        f.look.ao_distance_voxels = parse_double(*reach, "--ao-distance");
        if (!(f.look.ao_distance_voxels > 0)) throw Error("--ao-distance", "expected a positive distance in voxels, found '" + *reach + "'");
    }
    for (const std::string& a : args.values("--opacity")) {
        const double alpha = parse_double(a, "--opacity");
        if (!(alpha >= 0 && alpha <= 1)) throw Error("--opacity", "expected an opacity in [0, 1], found '" + a + "'");
        f.look.opacity.push_back(alpha);
    }
    for (const std::string& c : args.values("--clip")) {
        const std::vector<double> v = parse_list(c, "--clip");
        if (v.size() != 4 || (v[0] == 0 && v[1] == 0 && v[2] == 0))
            throw Error("--clip", "expected NX,NY,NZ,D with a non-zero normal, found '" + c + "'");
        f.clip_planes.push_back({{v[0], v[1], v[2]}, v[3]});
    }
    f.clip_cap = args.flag("--clip-cap");
    if (f.clip_cap && f.clip_planes.empty()) throw Error("--clip-cap", "caps the cut faces of --clip planes; give at least one --clip");
    if (f.clip_cap && f.look.composites())
        throw Error("--clip-cap", "does not combine with --opacity below 1 (translucent layers are traced again along each ray "
                                  "and would pass through the cap)");
    return f;
}

void write_look_json(JsonWriter& j, const LookFlags& flags) {
    const Look& look = flags.look;
    const std::vector<ClipPlane>& clip_planes = flags.clip_planes;
    if (!look.active() && clip_planes.empty()) return;
    j.key("look").begin_object().field("shadows", look.shadows).field("ao", look.ao_samples);
    j.field("ao_distance_voxels", look.ao_distance_voxels).key("opacity").array(look.opacity);
    j.key("clip").begin_array();
    for (const ClipPlane& c : clip_planes) j.array(std::array<double, 4>{c.normal[0], c.normal[1], c.normal[2], c.d});
    j.end_array().field("clip_cap", flags.clip_cap).end_object();
}

void write_look_stats_json(JsonWriter& j, const LookStats& stats) {
    j.key("secondary").begin_object().field("seconds", stats.seconds).field("shadow_rays", stats.shadow_rays);
    j.field("ao_rays", stats.ao_rays).field("layer_rays", stats.layer_rays).end_object();
}

void print_look_stats(const LookStats& s) {
    std::fprintf(stderr, "  look: %.3f s for %llu secondary rays (%llu shadow, %llu ambient occlusion, %llu past translucent surfaces)\n",
                 s.seconds, (unsigned long long)s.secondary_rays(), (unsigned long long)s.shadow_rays, (unsigned long long)s.ao_rays,
                 (unsigned long long)s.layer_rays);
}

}  // namespace octiso::cli
