#!/usr/bin/python3
"""Layers that only point down (docs/ARCHITECTURE.md, "Layers"): every #include "..." of a file in
include/octiso/ or src/ must name a file of its own layer or a lower one. Prints each upward
include and exits 1 if there is any; run by ctest (LayersPointDown).

    scripts/check_layers.py [REPO_ROOT]"""
import os
import re
import sys

# Lowest first. A file belongs to the first layer whose prefix matches its path.
LAYERS = [
    ("base", ["include/octiso/error.h", "include/octiso/inline.h", "include/octiso/limits.h", "include/octiso/volume.h",
              "include/octiso/tiles.h", "include/octiso/frame.h", "include/octiso/camera.h",
              "include/octiso/root_finder.h", "include/octiso/step_pattern.h", "include/octiso/output_guard.h",
              "include/octiso/version.h", "src/math/", "src/util/"]),
    ("volume", ["include/octiso/loaded_volume.h", "include/octiso/synthetic.h", "src/volume/"]),
    ("octree", ["include/octiso/octree.h", "include/octiso/build.h", "include/octiso/decode.h", "src/octree/"]),
    ("format", ["include/octiso/oct_file.h", "include/octiso/verify.h", "src/format/"]),
    ("kernels", ["src/render/cell.h", "src/render/roots.h", "src/render/cell_hit.h", "src/render/cell_dda.h",
                 "src/render/lod.h", "src/render/live_children.h", "src/render/packet_size.h", "src/render/packet_start.h", "src/render/pending_roots.h", "src/render/simd4.h",
                 "src/render/traverse.h",
                 "src/render/root_finder.cpp"]),
    ("scene", ["src/scene/"]),
    ("frame", ["include/octiso/render.h", "include/octiso/debug_trace.h", "include/octiso/antialias.h",
               "include/octiso/bricks.h", "include/octiso/depth_composite.h", "src/render/"]),
    ("api", ["include/octiso/any_octree.h", "include/octiso/value_stats.h", "include/octiso/shading.h", "include/octiso/look.h",
             "include/octiso/clip_cap.h", "src/api/"]),
    ("io", ["include/octiso/reader.h", "include/octiso/image.h", "include/octiso/volume_writer.h", "src/io/"]),
    ("convert", ["include/octiso/convert.h", "src/convert/"]),
    ("reference", ["src/reference/"]),
    ("view", ["src/view/"]),
    ("mpi", ["src/mpi/"]),
    ("tools", ["src/cli/"]),
]


def layer_of(path):
    for i, (_, prefixes) in enumerate(LAYERS):
        if any(path == p or (p.endswith("/") and path.startswith(p)) for p in prefixes):
            return i
    return None


def resolve(include):
    """An include as written ("octiso/x.h", "render/x.h") -> its path in the repository."""
    return "include/" + include if include.startswith("octiso/") else "src/" + include


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    bad = []
    for top in ("include/octiso", "src"):
        for dirpath, _, files in os.walk(os.path.join(root, top)):
            for name in files:
                path = os.path.relpath(os.path.join(dirpath, name), root)
                if not name.endswith((".h", ".cpp")) or path.startswith("src/cli/"):
                    continue
                mine = layer_of(path)
                if mine is None:
                    bad.append(f"{path}: in no layer (add it to scripts/check_layers.py)")
                    continue
                for line in open(os.path.join(root, path), encoding="utf-8"):
                    m = re.match(r'\s*#\s*include\s+"([^"]+)"', line)
                    if not m:
                        continue
                    target = resolve(m.group(1))
                    theirs = layer_of(target)
                    if theirs is not None and theirs > mine:
                        bad.append(f"{path} ({LAYERS[mine][0]}) includes {m.group(1)} ({LAYERS[theirs][0]})")
    for b in bad:
        print(b)
    print(f"check_layers: {len(bad)} upward include(s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
