#!/usr/bin/python3
"""A change of the tracer measured alone: two builds of octiso-render (A, the one before the change,
e.g. a worktree of the previous commit; B, this one) render the same orbit of each file, PAIRS times,
A and B interleaved and the order flipped every pair so that drift on a shared machine hits both
alike. Per file it prints the minimum and median over the runs of the mean tile-loop time per frame
(`phases.trace` of --json), B / A, and whether the depth and normal images of both builds are the
same pixels (idiff -fail 0: a change meant to keep the image must).

    scripts/build_ab.py --a /work/wt-old/build/octiso-render [--b build/octiso-render] [--pairs 5]
                        [--threads 1] [--size 512x512] [--orbit 8] [--flags '--no-embree']
                        [--colour] [--phase trace|shade|other|frame] [--cold] [--results DIR] [--tag NAME]
                        FILE.oct[,B_FILE.oct]@ISO ...

--colour also writes the colour image and compares it; --phase shade times the shading pass instead
of the tile loop: with --colour --flags '--no-embree --ao 4' that is the ambient-occlusion rays,
single rays from the hits in random directions (the renderer's incoherent rays). --phase frame times
the whole frame (frame_seconds: tile loops, shading, and the rest such as the frame's buffers),
--phase other only that rest. --cold drops the file from the page cache before every run
(posix_fadvise DONTNEED: clean pages nobody maps) and times the first frame's whole wall time
(frame_seconds of frame 0: its page faults' reads and, under --verify touched, its block checks),
what a user waits for on opening a file; give --orbit 1.

FILE.oct,B_FILE.oct: a format change, each build on its own conversion of the same voxels (A on FILE,
B on B_FILE); the images are compared all the same.

--results DIR writes build_ab[_NAME].json there (default: a temporary folder, printed). Used for
BENCHMARKS.md, "Packet traversal and ISA kernels" (the cap corner lattice)."""
import argparse
import json
import os
import platform
import statistics
import subprocess
import tempfile


def kinds(a):
    return [("depth", "exr"), ("normal", "exr")] + ([("colour", "png")] if a.colour else [])


def evict(path):
    fd = os.open(path, os.O_RDONLY)
    try:
        os.posix_fadvise(fd, 0, 0, os.POSIX_FADV_DONTNEED)
    finally:
        os.close(fd)


def render(binary, path, iso, a, outdir, tag):
    if a.cold:
        evict(path)
    outputs = {"depth": "--depth", "normal": "--normal", "colour": "-o"}
    cmd = [binary, path, "--iso", iso, "--orbit", str(a.orbit), "--threads", str(a.threads), "--size", a.size, "--json"]
    for kind, ext in kinds(a):
        cmd += [outputs[kind], os.path.join(outdir, f"{tag}_{kind}_%d.{ext}")]
    out = subprocess.run(cmd + a.flags.split(), check=True, capture_output=True, text=True).stdout
    frames = json.loads(out)["frames"]
    if a.cold:
        return frames[0]["frame_seconds"]
    if a.phase == "frame":   # the whole frame: tile loops, shading and the rest (buffers)
        return sum(f["frame_seconds"] for f in frames) / len(frames)
    return sum(f["phases"][a.phase] for f in frames) / len(frames)


def same_pixels(outdir, a):
    for kind, ext in kinds(a):
        for i in range(a.orbit):
            pa, pb = (os.path.join(outdir, f"{t}_{kind}_{i}.{ext}") for t in ("A", "B"))
            if subprocess.run(["idiff", "-fail", "0", "-warn", "0", pa, pb], capture_output=True).returncode != 0:
                return False
    return True


def main():
    p = argparse.ArgumentParser()
    p.add_argument("datasets", nargs="+", help="FILE.oct[,B_FILE.oct]@ISO")
    p.add_argument("--a", required=True, help="octiso-render before the change")
    p.add_argument("--b", default="build/octiso-render", help="octiso-render with the change")
    p.add_argument("--pairs", type=int, default=5)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--size", default="512x512")
    p.add_argument("--orbit", type=int, default=8)
    p.add_argument("--flags", default="--no-embree")
    p.add_argument("--colour", action="store_true", help="also write and compare the colour image")
    p.add_argument("--phase", default="trace", choices=["trace", "shade", "other", "frame"],
                   help="the phase timed (phases of --json; frame: frame_seconds, all of them)")
    p.add_argument("--cold", action="store_true", help="each run from a cold page cache, its first frame's wall time")
    p.add_argument("--results")
    p.add_argument("--tag", default="", help="the JSON is build_ab_TAG.json")
    a = p.parse_args()
    if a.cold and a.orbit != 1:
        p.error("--cold times a process's first frame: give --orbit 1")
    rows = []
    print(f"| file | iso | A min / median ms | B min / median ms | B / A (min) | B / A (median) | same pixels |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as outdir:
        for spec in a.datasets:
            paths, iso = spec.rsplit("@", 1)
            path, b_path = (paths.split(",", 1) + [None])[:2] if "," in paths else (paths, paths)
            t = {"A": [], "B": []}
            for pair in range(a.pairs):
                order = ("A", "B") if pair % 2 == 0 else ("B", "A")
                for tag in order:
                    t[tag].append(render(a.a if tag == "A" else a.b, path if tag == "A" else b_path, iso, a, outdir, tag))
            same = same_pixels(outdir, a)
            row = {"file": path, "b_file": b_path, "iso": float(iso), "a_seconds": t["A"], "b_seconds": t["B"],
                   "b_over_a_min": min(t["B"]) / min(t["A"]),
                   "b_over_a_median": statistics.median(t["B"]) / statistics.median(t["A"]), "same_pixels": same}
            rows.append(row)
            print(f"| {os.path.basename(path)} | {iso} | {1e3 * min(t['A']):.1f} / {1e3 * statistics.median(t['A']):.1f} | "
                  f"{1e3 * min(t['B']):.1f} / {1e3 * statistics.median(t['B']):.1f} | {row['b_over_a_min']:.3f} | "
                  f"{row['b_over_a_median']:.3f} | {'yes' if same else 'NO'} |")
    results = a.results or tempfile.mkdtemp(prefix="octiso_build_ab_")
    os.makedirs(results, exist_ok=True)
    out = os.path.join(results, f"build_ab_{a.tag}.json" if a.tag else "build_ab.json")
    with open(out, "w") as f:
        json.dump({"a": a.a, "b": a.b, "pairs": a.pairs, "threads": a.threads, "size": a.size, "orbit": a.orbit,
                   "flags": a.flags, "phase": "cold first frame" if a.cold else a.phase, "colour": a.colour, "machine": platform.processor() or platform.machine(), "rows": rows}, f, indent=1)
    print(f"JSON: {out}")
    return 0 if all(r["same_pixels"] for r in rows) else 1


if __name__ == "__main__":
    raise SystemExit(main())
