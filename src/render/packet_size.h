// The largest packet of rays the octree traversal takes in one call: what the tracer sizes its
// per-packet arrays by (traverse.h) and the renderer its pixel blocks (renderer.cpp, look.cpp).
#pragma once

namespace octiso {

/// Rays per trace_packet call at most: the renderer's direct packets of 4x4 pixels (Embree's
/// rtcIntersect8 hands over 8). 16 lanes share each node load, cull, cap parent and corner lattice
/// among twice the rays of 8: 0.92-0.95 x the frame time at 1 thread, 0.86-1.00 x at 2 (min of 7
/// pairs; build_ab_packet16_rerun.json, build_ab_packet16_2threads.json), 0.87-0.92 x in the
/// portable kernel (build_ab_packet16_baseline_isa.json); 32 lanes (8x4) gained nothing more
/// (0.98-1.03 x against 16, build_ab_packet32.json).
inline constexpr int kMaxTracePacket = 16;

}  // namespace octiso
