#!/usr/bin/python3
"""octiso-render under mpirun (issue 15), against the single-process images, bit for bit:
series across ranks (--distribute steps, a rank with no step), one frame across ranks (image,
sort-first) and one volume across ranks (data, sort-last: an empty brick, a surface lying exactly
on a brick face), with 2 ranks and with 4 oversubscribed; and a failure reported once, exit 2.
Colour is compared byte for byte (PNG), depth and normal pixel for pixel (idiff -fail 0: any
difference fails; EXR headers carry a timestamp). Run by ctest (MpiModes).

    mpi_modes.py RENDER CONVERT MPIRUN"""
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile

RENDER, CONVERT, MPIRUN = sys.argv[1:4]
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")
failures = []


def run(cmd, expect=0):
    p = subprocess.run(cmd, env=ENV, capture_output=True, text=True)
    if p.returncode != expect:
        failures.append(f"{' '.join(cmd)}: exit {p.returncode}, expected {expect}\n{p.stderr[-3000:]}")
    return p


def same_png(a, b):
    with open(a, "rb") as fa, open(b, "rb") as fb:
        return fa.read() == fb.read()


def same_pixels(a, b):
    return subprocess.run(["idiff", "-fail", "0", "-warn", "0", a, b], capture_output=True).returncode == 0


def compare(tag, ref_prefix, got_prefix, names):
    for n in names:
        a, b = ref_prefix + n, got_prefix + n
        if not os.path.exists(b):
            failures.append(f"{tag}: {b} was not written")
            continue
        ok = same_png(a, b) if n.endswith(".png") else same_pixels(a, b)
        if not ok:
            failures.append(f"{tag}: {b} differs from the single-process {a}")


def mpi(ranks, args):
    return [MPIRUN, "--oversubscribe", "-np", str(ranks), RENDER] + args


def raw_volume(path, dims, f):
    nx, ny, nz = dims
    with open(path, "wb") as out:
        for z in range(nz):
            for y in range(ny):
                out.write(struct.pack(f"<{nx}f", *[f(x, y, z) for x in range(nx)]))


def main():
    tmp = tempfile.mkdtemp(prefix="octiso_mpi_")
    os.chdir(tmp)
    run([CONVERT, "--synthetic", "plume-series:40,3", "-o", "series.oct"])
    # f = x: the isosurface 16 is the plane x = 16, the face between bricks for 2 and 4 ranks.
    raw_volume("plane.raw", (33, 12, 10), lambda x, y, z: float(x))
    run([CONVERT, "plane.raw", "--dims", "33,12,10", "--type", "f32", "-o", "plane.oct"])
    # 2 cells along x: with 4 ranks two bricks are empty.
    raw_volume("thin.raw", (3, 20, 20), lambda x, y, z: float(((y - 9.5) ** 2 + (z - 9.5) ** 2) ** 0.5 + x))
    run([CONVERT, "thin.raw", "--dims", "3,20,20", "--type", "f32", "-o", "thin.oct"])
    look = ["--size", "96x80", "--threads", "1"]

    # Series: every step's image, and the JSON's per-rank report; 1 step leaves rank 1 idle.
    run([RENDER, "series.oct", "--iso", "90", "--steps", "0:2", "-o", "ref_%02d.png", "--depth", "ref_%02d.exr"] + look)
    for ranks in (2, 4):
        p = run(mpi(ranks, ["series.oct", "--iso", "90", "--steps", "0:2", "-o", f"s{ranks}_%02d.png",
                            "--depth", f"s{ranks}_%02d.exr", "--json"] + look))
        compare(f"steps x{ranks}", "ref_", f"s{ranks}_", [f"{k:02d}.png" for k in range(3)] + [f"{k:02d}.exr" for k in range(3)])
        if p.returncode == 0:
            report = json.loads(p.stdout)
            steps = sorted(s for r in report["per_rank"] for s in r["steps"])
            if steps != [0, 1, 2] or len(report["per_rank"]) != ranks or [f["step"] for f in report["frames"]] != [0, 1, 2]:
                failures.append(f"steps x{ranks}: the report's steps are wrong: {report['per_rank']}")
    run([RENDER, "series.oct", "--iso", "90", "--steps", "1:1", "-o", "one_%d.png"] + look)
    run(mpi(2, ["series.oct", "--iso", "90", "--steps", "1:1", "-o", "idle_%d.png"] + look))
    compare("steps, a rank without a step", "one_", "idle_", ["1.png"])

    # One frame: sort-first and sort-last, colour (both shadings, 2 samples) and both AOVs.
    cases = [("series.oct", ["--iso", "90,150", "--spp", "2"]),
             ("series.oct", ["--iso", "90", "--shading", "headlight", "--azimuth", "170"]),
             ("plane.oct", ["--iso", "16", "--azimuth", "10"]),   # the surface on the brick face
             ("plane.oct", ["--iso", "16", "--azimuth", "190", "--shading", "headlight"]),
             ("thin.oct", ["--iso", "6"])]                       # empty bricks at 4 ranks
    for c, (name, extra) in enumerate(cases):
        outs = lambda p: ["-o", f"{p}.png", "--depth", f"{p}_d.exr", "--normal", f"{p}_n.exr"]
        run([RENDER, name] + extra + look + outs(f"ref{c}"))
        for mode in ("image", "data"):
            for ranks in (2, 4):
                got = f"{mode}{ranks}_{c}"
                run(mpi(ranks, [name, "--distribute", mode] + extra + look + outs(got)))
                compare(f"{mode} x{ranks} {name} {' '.join(extra)}", f"ref{c}", got, [".png", "_d.exr", "_n.exr"])

    # A failure: one line, once, exit 2, no image.
    p = run(mpi(2, ["series.oct", "--iso", "90", "--distribute", "bricks", "-o", "never.png"] + look), expect=2)
    lines = [l for l in p.stderr.splitlines() if l.startswith("octiso-render:")]
    if len(lines) != 1 or "--distribute" not in lines[0]:
        failures.append(f"a bad flag under mpirun should be reported once, got: {lines}")
    if os.path.exists("never.png"):
        failures.append("a refused run wrote its image")
    # An isovalue outside the steps' range: the ranks split the validation and unite the ranges,
    # then every rank refuses alike; one line, exit 2, no frame.
    p = run(mpi(2, ["series.oct", "--iso", "9999", "--steps", "0:2", "-o", "never_%02d.png"] + look), expect=2)
    lines = [l for l in p.stderr.splitlines() if l.startswith("octiso-render:")]
    if len(lines) != 1 or "outside the data range" not in lines[0]:
        failures.append(f"an isovalue outside the range under mpirun should be refused once, got: {lines}")
    if any(n.startswith("never_") for n in os.listdir(".")):
        failures.append("a refused series wrote a frame")

    os.chdir("/")
    shutil.rmtree(tmp)
    for f in failures:
        print("FAIL:", f)
    print(f"mpi_modes: {len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
