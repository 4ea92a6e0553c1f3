#!/usr/bin/python3
"""Counts a candidate u8 cap-parent layout for issue 19 from a volume's voxels, without building it:
bounds of each child's own 2x2x2 block instead of its 3x3x3 corner lattice ("block bounds").

Format 6 stores per cap parent 8 scalars, 8 lattice minima and maxima, a child offset, a child mask
and the caps' width (28 bytes), and the caps anchored at a lattice bound (BENCHMARKS.md, "The
compact octree, format 6"). With the children's own block ranges instead:
- a cap's base is its block minimum and its width the bits of its block range, so each cap takes
  exactly bits(max - min) bytes (8 deltas) with nothing stored for width or anchor;
- a child with min == max is a scalar leaf of that value: the scalars and the child mask follow
  from the bounds (the level-of-detail sample of a cap, its voxel 0, is in the cap);
- the cull, which needs the range of a child's cells' corners, takes the union of the block ranges
  of the siblings its lattice reaches (the blocks s with s >= c on every axis) and, for the
  lattice voxels beyond the parent's upper faces, ranges of the parent's forward shell stored in
  the record: one range for the whole shell (2 bytes) or one per face (6 bytes). Conservative
  (never narrower than the lattice range), so culling stays exact, but looser.
Counted: the cap bytes, the record bytes, the file's size from `octiso-info`'s numbers, and per
isovalue how many children of the cap parents pass the cull with the lattice ranges (today) and
with the looser ranges (each extra one is a cap visit a ray may pay for).
Input: a raw x-fastest u8 array whose sides are a multiple of 4 (octiso-info FILE.oct --extract-raw).
Usage: scripts/block_bounds_count.py VOLUME.raw NX NY NZ --file-bytes B --cap-bytes C --iso V [--iso V]
       [--json OUT.json]
"""
import argparse
import json

import numpy as np

from cap_layout_count import bit_length, box_range, cube, read_volume   # same folder


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("raw")
    ap.add_argument("dims", nargs=3, type=int, metavar="N")
    ap.add_argument("--file-bytes", type=int, required=True, help="the format-6 file's bytes (octiso-info)")
    ap.add_argument("--cap-bytes", type=int, required=True, help="its cap bytes (octiso-info)")
    ap.add_argument("--iso", type=float, action="append", required=True)
    ap.add_argument("--json", help="write the counts here")
    a = ap.parse_args()
    nx, ny, nz = a.dims
    v = read_volume(a.raw, a.dims)

    # Per cap parent (4^3 voxels) and child octant (cx, cy, cz): block, lattice and loose ranges.
    octants = [(cx, cy, cz) for cx in (0, 1) for cy in (0, 1) for cz in (0, 1)]
    block = {c: box_range(v, 4, cube((2 * c[0], 2 * c[1], 2 * c[2]), 2)) for c in octants}
    lattice = {c: box_range(v, 4, cube((2 * c[0], 2 * c[1], 2 * c[2]), 3)) for c in octants}
    face = [box_range(v, 4, [(z, y, x) for z in range(5) for y in range(5) for x in range(5)
                             if (x, y, z)[axis] == 4]) for axis in range(3)]
    shell = (np.minimum(np.minimum(face[0][0], face[1][0]), face[2][0]),
             np.maximum(np.maximum(face[0][1], face[1][1]), face[2][1]))

    def loose(c, faces):
        """The cull's range of child c: the sibling blocks its lattice reaches, and the shell."""
        lo = hi = None
        for s in octants:
            if all(s[i] >= c[i] for i in range(3)):
                lo = block[s][0] if lo is None else np.minimum(lo, block[s][0])
                hi = block[s][1] if hi is None else np.maximum(hi, block[s][1])
        up = [axis for axis in range(3) if c[axis]]
        if up and faces == "shell":
            lo, hi = np.minimum(lo, shell[0]), np.maximum(hi, shell[1])
        for axis in up if faces == "faces" else []:
            lo, hi = np.minimum(lo, face[axis][0]), np.maximum(hi, face[axis][1])
        return lo, hi

    stored = {c: block[c][0] != block[c][1] for c in octants}
    # A cap parent is every 4^3 block that is not one value (the builder merges those into leaves).
    uniform = np.ones(block[octants[0]][0].shape, bool)
    for c in octants:
        uniform &= (block[c][0] == block[c][1]) & (block[c][0] == block[octants[0]][0])
    cap_parents = int((~uniform).sum())

    def file_bytes(record_bytes, cap_bytes):
        """The format-6 file with its cap-parent records and caps replaced by these."""
        return a.file_bytes - cap_parents * 28 - a.cap_bytes + record_bytes + cap_bytes

    def holds(lo, hi, iso):
        """The tracer's cull: an integer range holds iso where lo <= floor(iso) and hi >= ceil(iso)."""
        return (lo <= iso) & (iso <= hi)
    caps = int(sum(stored[c].sum() for c in octants))
    cap_bytes = int(sum(np.where(stored[c], bit_length(block[c][1] - block[c][0]), 0).sum() for c in octants))
    counts = {
        "file": a.raw,
        "dims": [nx, ny, nz],
        "raw_bytes": int(v.size),
        "cap_parents": cap_parents,
        "caps_stored": caps,
        "format6_file_bytes": a.file_bytes,
        "format6_cap_bytes": a.cap_bytes,
        "block_bounds_cap_bytes": cap_bytes,
        "layouts": {},
        "cull": [],
    }
    for faces, face_bytes in (("shell", 2), ("faces", 6)):
        record = 16 + face_bytes + 2   # block min[8], max[8], the shell ranges, child_offset
        total = file_bytes(cap_parents * record, cap_bytes)
        counts["layouts"][faces] = {"record_bytes": record, "file_bytes": total,
                                    "of_raw": round(total / v.size, 4)}
    # The same record with its 18 bounds (16 block bounds, the shell's two) stored relative to
    # the parent's own range (its 5x5x5 lattice, which its parent's record holds exactly), each
    # in as many bits as that range needs: nothing stored for the width.
    parent_lo, parent_hi = box_range(v, 4, cube((0, 0, 0), 5))
    rel_bits = bit_length(parent_hi - parent_lo)[~uniform]
    rel_record = int(((18 * rel_bits + 7) // 8 + 2).sum())
    total = file_bytes(rel_record, cap_bytes)
    counts["layouts"]["shell_relative"] = {"record_bytes_mean": round(rel_record / cap_parents, 2),
                                           "file_bytes": total, "of_raw": round(total / v.size, 4)}
    # A fixed 18-byte record: the 18 bounds as 7-bit codes relative to the parent's range in 16
    # bytes, then the child offset. A parent whose range needs 8 bits codes q = (x - lo) // 2 for
    # every bound (q <= 127) and decodes a lower bound as lo + 2q, an upper one as lo + 2q + 1
    # (at most 255): never narrower, so the cull stays conservative; its caps then count from the
    # decoded minimum to the decoded maximum, so they may need a bit more.
    halve = np.zeros(uniform.shape, bool)
    halve[~uniform] = rel_bits > 7
    fixed_caps = 0
    for c in octants:
        lo, hi = block[c]
        lo_r = np.where(halve, parent_lo + ((lo - parent_lo) // 2) * 2, lo)
        hi_r = np.where(halve, np.minimum(parent_lo + ((hi - parent_lo) // 2) * 2 + 1, 255), hi)
        fixed_caps += int(np.where(stored[c], bit_length(hi_r - lo_r), 0).sum())
    total = file_bytes(cap_parents * 18, fixed_caps)
    counts["layouts"]["shell_relative_fixed18"] = {"record_bytes": 18, "cap_bytes": fixed_caps,
                                                   "parents_in_steps_of_2": int(halve.sum()),
                                                   "file_bytes": total, "of_raw": round(total / v.size, 4)}
    for iso in a.iso:
        row = {"iso": iso}
        live = {"lattice": 0, "shell": 0, "faces": 0}
        for c in octants:
            lo, hi = lattice[c]
            live["lattice"] += int((holds(lo, hi, iso) & ~uniform).sum())
            for faces in ("shell", "faces"):
                lo, hi = loose(c, faces)
                live[faces] += int((holds(lo, hi, iso) & ~uniform).sum())
        row["children_live"] = live
        row["extra_vs_lattice"] = {k: round(live[k] / live["lattice"], 3) for k in ("shell", "faces")}
        counts["cull"].append(row)
    print(json.dumps(counts, indent=1))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(counts, f, indent=1)


if __name__ == "__main__":
    main()
