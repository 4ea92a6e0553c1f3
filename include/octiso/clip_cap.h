// Caps on the cut faces of clip planes (octiso-render --clip-cap, issue 17 item 7): where a plane
// cuts through the inside of an isosurface, the cut is drawn as a flat face, as a solid cut open
// shows its interior. "Inside" is the side of larger values (value >= V: bone inside skin in CT,
// grey matter in an MRI template); a scale with a negative slope turns it round in stored values.
// A pass over a traced frame's depth (and normal) AOVs: the tracer and its rays stay as they are;
// shading then colours a cap with the innermost isovalue whose inside holds it (shading.h).
#pragma once

#include <cstddef>
#include <vector>

#include "octiso/any_octree.h"
#include "octiso/camera.h"
#include "octiso/frame.h"
#include "octiso/render.h"

namespace octiso {

struct ClipCap {
    std::vector<ClipPlane> planes;   ///< the frame's clip planes (RenderOptions::clip_planes)
    bool inside_above = true;        ///< inside is stored value >= V (false: <= V, a negative value scale)
};

/// The isovalue a point of value `v` (stored) lies inside, the innermost when several hold it: the
/// largest V <= v (inside_above), else the smallest V >= v; -1 when none (or v is NaN).
int cap_isovalue(double v, const std::vector<double>& isovalues, bool inside_above);

/// Caps `frame`, traced by `tree` with `isovalues` (stored values) through `camera` (its
/// pixel_offset included) and the clip planes of `cap`: every pixel whose primary ray enters the
/// kept set through a plane at a point of the data box (closed) where the trilinear field lies
/// inside an isovalue gets depth t (the plane's, as clip_ray's t_min, stored as float) and, when
/// the frame has one, normal = the plane's unit normal (it faces the ray). A hit of the frame is
/// never nearer than that t, so the cap replaces whatever the pixel showed. Needs frame.depth;
/// returns the number of pixels capped. Thread-safe for distinct frames.
size_t cap_clip_planes(const AnyOctree& tree, const std::vector<double>& isovalues, const ClipCap& cap, const Camera& camera,
                       Frame& frame);

}  // namespace octiso
