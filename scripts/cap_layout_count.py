#!/usr/bin/python3
"""Counts what a u8 volume's caps and cap parents would take in the candidate layouts of issue 19
(BENCHMARKS.md, "The compact octree, format 6"), from its voxels, without building them.

Input: a raw x-fastest u8 array (e.g. `octiso-info FILE.oct --extract-raw OUT.raw`) whose sides
are a multiple of 4. A cap is the 2x2x2 voxel block at even coordinates; it is stored unless its
8 voxels are equal (then it merges into a scalar leaf, as the builder does); its child bounds are
the range of its 3x3x3 corner lattice (its cells' corners, cut at the data's last voxel). Format 6
gives every cap of a parent the width of the widest, counted from the parent's better anchor (the
lower or the upper bound); `format6_cap_bytes` reproduces the file's cap bytes (mixing 256^3:
1 818 440, `octiso-info`). The other counts are the alternatives: per-cap widths with each cap's
better anchor (before the widths' own storage), widths derived from the bounds, and the bits that
child bounds stored relative to their parent's range (5x5x5 lattice) would need.
Usage: scripts/cap_layout_count.py VOLUME.raw NX NY NZ [--json OUT.json]
"""
import argparse
import json

import numpy as np


def bit_length(a):
    """Bits to hold each non-negative value of a (0 for 0)."""
    out = np.zeros(a.shape, np.int64)
    v = a.astype(np.int64)
    while (v > 0).any():
        out += v > 0
        v >>= 1
    return out


def box_range(v, step, offsets):
    """Min and max over the voxels at each block origin (step apart) + each (dz, dy, dx) of
    offsets, cut at the data's last voxel."""
    nz, ny, nx = v.shape
    lo = hi = None
    for dz, dy, dx in offsets:
        iz = np.minimum(np.arange(0, nz, step) + dz, nz - 1)
        iy = np.minimum(np.arange(0, ny, step) + dy, ny - 1)
        ix = np.minimum(np.arange(0, nx, step) + dx, nx - 1)
        s = v[np.ix_(iz, iy, ix)]
        lo = s if lo is None else np.minimum(lo, s)
        hi = s if hi is None else np.maximum(hi, s)
    return lo, hi


def cube(origin, width):
    """The (dz, dy, dx) offsets of the width^3 voxels from origin (x, y, z)."""
    ox, oy, oz = origin
    return [(oz + z, oy + y, ox + x) for z in range(width) for y in range(width) for x in range(width)]


def lattice_range(v, step, width):
    """Min and max over the width^3 voxels from each block origin (step apart), cut at the data."""
    return box_range(v, step, cube((0, 0, 0), width))


def read_volume(raw, dims):
    """The raw x-fastest u8 array as (z, y, x) int64, its sides checked to be multiples of 4."""
    nx, ny, nz = dims
    if min(dims) < 4 or any(n % 4 for n in dims):
        raise SystemExit(f"{raw}: sides must be multiples of 4, got {nx}x{ny}x{nz}")
    try:
        v = np.fromfile(raw, dtype=np.uint8)
    except OSError as e:
        raise SystemExit(f"{raw}: {e.strerror or e}")
    if v.size != nx * ny * nz:
        raise SystemExit(f"{raw}: {v.size} bytes, not {nx}x{ny}x{nz}")
    return v.reshape(nz, ny, nx).astype(np.int64)


def blocks(a, side):
    """a (z, y, x) split into blocks of side^3: axes (bz, side, by, side, bx, side)."""
    nz, ny, nx = a.shape
    return a.reshape(nz // side, side, ny // side, side, nx // side, side)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("raw")
    ap.add_argument("dims", nargs=3, type=int, metavar="N")
    ap.add_argument("--json", help="write the counts here")
    a = ap.parse_args()
    nx, ny, nz = a.dims
    v = read_volume(a.raw, a.dims)

    own = blocks(v, 2)
    own_lo, own_hi = own.min(axis=(1, 3, 5)), own.max(axis=(1, 3, 5))
    stored = own_lo != own_hi
    bound_lo, bound_hi = lattice_range(v, 2, 3)
    from_lower = bit_length(own_hi - bound_lo)   # deltas counted up from the lower bound
    from_upper = bit_length(bound_hi - own_lo)   # ... down from the upper bound

    def per_parent_max(x):
        return blocks(np.where(stored, x, 0), 2).max(axis=(1, 3, 5))

    caps_per_parent = blocks(stored, 2).sum(axis=(1, 3, 5))
    parent_width = np.minimum(per_parent_max(from_lower), per_parent_max(from_upper))
    # A cap of width b takes b bytes, one of them in its parent's scalar slot (format 6).
    format6 = int((caps_per_parent * np.maximum(parent_width - 1, 0)).sum())
    per_cap = int(np.where(stored, np.maximum(np.minimum(from_lower, from_upper) - 1, 0), 0).sum())
    derived = int(np.where(stored, np.maximum(bit_length(bound_hi - bound_lo) - 1, 0), 0).sum())
    has_caps = caps_per_parent > 0
    parent_lo, parent_hi = lattice_range(v, 4, 5)
    relative_bits = bit_length(parent_hi - parent_lo)[has_caps]
    # 16 bounds of 8 bits each today; at b bits each they would save 2 * (8 - b) bytes.
    relative_saving = int((2 * (8 - relative_bits)).sum())
    counts = {
        "file": a.raw,
        "dims": [nx, ny, nz],
        "raw_bytes": int(v.size),
        "caps_stored": int(stored.sum()),
        "cap_parents_with_caps": int(has_caps.sum()),
        "format6_cap_bytes": format6,
        "per_cap_width_best_anchor_cap_bytes": per_cap,
        "width_from_bounds_cap_bytes": derived,
        "relative_bounds_bits_histogram": np.bincount(relative_bits, minlength=9).tolist(),
        "relative_bounds_saving_bytes_before_width_field": relative_saving,
    }
    for k, x in counts.items():
        print(f"{k:50s} {x}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(counts, f, indent=1)


if __name__ == "__main__":
    main()
