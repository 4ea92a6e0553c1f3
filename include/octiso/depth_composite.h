// Sort-last compositing by depth (issue 15, octiso-render --distribute data): each rank renders
// the cells of its brick (octiso/bricks.h) into a full frame, packs it into composite samples, and
// the samples of all ranks are reduced pixel by pixel to the nearest one. The reduction is
// commutative and associative (nearest depth, then lowest brick ordinal), so any reduction tree
// (MPI_Reduce_scatter, binary swap) gives the same image. Transport is the caller's (src/mpi/).
//
// Why the result is the single-process image bit for bit: a brick traces its cells with the very
// intervals the whole volume uses (RenderOptions::owned_cells), and each cell's piece of the ray is
// half-open, so the whole volume's first hit lies in one brick, which finds it, while every other
// brick's first hit lies in a later cell, strictly farther (a miss is +inf everywhere).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "octiso/frame.h"

namespace octiso {

/// What a composite sample carries besides its depth: the colour and/or the normal AOV.
struct CompositeLayout {
    bool colour = false;
    bool normal = false;
    /// Bytes of one sample: depth (f32) and ordinal (u32), then sRGB (4 bytes, one unused) and
    /// the normal (3 x f32) where asked.
    size_t sample_bytes() const { return 8 + (colour ? 4 : 0) + (normal ? 12 : 0); }
    /// The layout whose sample_bytes() is `bytes` (8, 12, 20 or 24): an MPI reduction operator
    /// sees only the datatype's size.
    static CompositeLayout from_sample_bytes(size_t bytes) { return {(bytes - 8) % 12 != 0, bytes >= 20}; }
};

/// Writes the samples of `frame` (which must hold depth, and colour / normal where `layout` asks)
/// tagged with `ordinal` (the brick's order: at equal depth the lower wins) into `out`, whose size
/// must be pixels x layout.sample_bytes(). Throws Error(..., Other) on a size mismatch.
void pack_composite(const Frame& frame, uint32_t ordinal, const CompositeLayout& layout, std::span<std::byte> out);

/// inout[i] = the nearer of in[i] and inout[i] for `count` samples: the reduction operator.
void composite_nearer(const std::byte* in, std::byte* inout, size_t count, const CompositeLayout& layout);

/// Writes `samples` (pixels x layout.sample_bytes()) back into the outputs `frame` holds: depth if
/// frame.depth is sized, rgb and normal where the layout has them and the frame is sized for them;
/// stats.hits becomes the count of finite depths. Throws Error(..., Other) on a size mismatch.
void unpack_composite(std::span<const std::byte> samples, const CompositeLayout& layout, Frame& frame);

}  // namespace octiso
