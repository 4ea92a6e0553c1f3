#!/usr/bin/python3
"""Sweep five isovalues through a volume and save the images side by side with their frame times.

    examples/isovalue_sweep.py [VOLUME.nii.gz | RAW --dims NX,NY,NZ --dtype uint8] [-o sweep.png]

Without an input it uses the MRI template ch2better from Debian's mricron-data. A NIfTI file is
read with nibabel, a raw file with numpy; either way the array is built into an octree in place
(no copy), and one octiso.Renderer renders every frame, keeping its scene. Runs headless."""
import argparse
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import octiso  # noqa: E402

DEFAULT = "/usr/share/mricron/templates/ch2better.nii.gz"


def load(path, dims, dtype):
    """A [z, y, x] array and its voxel spacing (x, y, z)."""
    if path.endswith((".nii", ".nii.gz")):
        import nibabel
        image = nibabel.load(path)
        data = np.asanyarray(image.dataobj)            # stored values, NIfTI order [x, y, z]
        return np.ascontiguousarray(data.transpose(2, 1, 0)), tuple(float(s) for s in image.header.get_zooms()[:3])
    nx, ny, nz = dims
    return np.fromfile(path, dtype=dtype).reshape(nz, ny, nx), (1.0, 1.0, 1.0)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("input", nargs="?", default=DEFAULT)
    p.add_argument("--dims", type=lambda s: tuple(int(v) for v in s.split(",")))
    p.add_argument("--dtype", default="uint8")
    p.add_argument("-o", "--output", default="sweep.png")
    p.add_argument("--size", type=int, default=384)
    args = p.parse_args()
    if not os.path.exists(args.input):
        sys.exit(f"{args.input}: no such file (install mricron-data or name a volume)")

    volume, spacing = load(args.input, args.dims, args.dtype)
    tree = octiso.build(volume, spacing=spacing)
    lo, hi = tree.info()["value_range"]
    isovalues = [lo + (hi - lo) * f + 0.5 for f in (0.1, 0.25, 0.4, 0.55, 0.7)]
    renderer = octiso.Renderer(tree, isovalues[0], size=(args.size, args.size))
    camera = octiso.Camera.frame(tree, size=(args.size, args.size))

    fig, axes = plt.subplots(1, len(isovalues), figsize=(3 * len(isovalues), 3.4))
    for ax, iso in zip(axes, isovalues):
        renderer.iso = iso
        frame = renderer.render(camera)
        ax.imshow(frame.rgb)
        ax.set_title(f"iso {iso:g}\n{frame.seconds * 1e3:.0f} ms, {frame.hits} hits", fontsize=9)
        ax.axis("off")
    fig.suptitle(f"{os.path.basename(args.input)}  {volume.shape[::-1]} {volume.dtype}", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.9))
    fig.savefig(args.output, dpi=100)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
