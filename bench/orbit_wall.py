#!/usr/bin/python3
"""Whole orbits as a user runs them: two builds of octiso-render (A before a change, B after) each
render `octiso-render FILE --iso ISO --size S --zoom Z --threads T --orbit N -o f_%d.png --json`,
A and B interleaved and the order flipped every round, and the table gives the process's wall time
(min / median over the rounds), B / A, the frames' summed `phases.write` and `phases.trace`, and
the bytes of the PNG files. The writer thread encodes frame k while frame k+1 is traced
(src/cli/frame_writer.h), so a change of the encoder shows here and not in build_ab.py's trace
times; each PNG of B must decode to the pixels of A's (exit 1 otherwise).

    bench/orbit_wall.py --a OLD/octiso-render [--b build/octiso-render] [--rounds 5] [--orbit 8]
                        [--aovs] [--results DIR] FILE.oct@ISO:SIZE[:ZOOM[:THREADS]] ...

--aovs also writes each frame's depth and normal as OpenEXR (`--depth d_%d.exr --normal n_%d.exr`);
their floats must be the same too (idiff -fail 0) and their bytes are counted with the PNGs'.

--results DIR writes orbit_wall.json there (default: a temporary folder, printed). Used for
BENCHMARKS.md, "Image writers"."""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time


def decoded(path):
    """The 8-bit pixels of a PNG (Debian's python3-pil, which scripts/setup.sh installs).
    Comparing the files' bytes instead would call two encoders' same pixels different."""
    from PIL import Image
    with Image.open(path) as im:
        return im.convert("RGB").tobytes()


def outputs(args):
    """The files one orbit writes."""
    names = [f"f_{i}.png" for i in range(args.orbit)]
    if args.aovs:
        names += [f"{kind}_{i}.exr" for kind in ("d", "n") for i in range(args.orbit)]
    return names


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--a", required=True)
    ap.add_argument("--b", default="build/octiso-render")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--orbit", type=int, default=8)
    ap.add_argument("--aovs", action="store_true")
    ap.add_argument("--results")
    ap.add_argument("cases", nargs="+")
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="orbit_wall.")
    cases = []
    for spec in args.cases:
        file_part, _, rest = spec.rpartition("@")
        fields = rest.split(":")
        iso, size = fields[0], fields[1]
        zoom = fields[2] if len(fields) > 2 else "1"
        threads = fields[3] if len(fields) > 3 else "2"
        cases.append({"name": spec, "file": file_part, "iso": iso, "size": size, "zoom": zoom, "threads": threads})
    runs = {c["name"]: {"a": [], "b": []} for c in cases}
    same = {c["name"]: True for c in cases}
    for r in range(args.rounds):
        for c in cases:
            order = [("a", args.a), ("b", args.b)] if r % 2 == 0 else [("b", args.b), ("a", args.a)]
            for side, binary in order:
                out = os.path.join(work, side)
                os.makedirs(out, exist_ok=True)
                cmd = [binary, c["file"], "--iso", c["iso"], "--size", f"{c['size']}x{c['size']}", "--zoom", c["zoom"],
                       "--threads", c["threads"], "--orbit", str(args.orbit), "-o", os.path.join(out, "f_%d.png"), "--json"]
                if args.aovs:
                    cmd += ["--depth", os.path.join(out, "d_%d.exr"), "--normal", os.path.join(out, "n_%d.exr")]
                t0 = time.perf_counter()
                report = json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)
                wall = time.perf_counter() - t0
                runs[c["name"]][side].append({
                    "wall": wall,
                    "write": sum(f["phases"]["write"] for f in report["frames"]),
                    "trace": sum(f["phases"]["trace"] for f in report["frames"]),
                    "bytes": sum(os.path.getsize(os.path.join(out, name)) for name in outputs(args))})
            if r == 0:
                for name in outputs(args):
                    a_file, b_file = os.path.join(work, "a", name), os.path.join(work, "b", name)
                    if name.endswith(".exr"):
                        equal = subprocess.run(["idiff", "-fail", "0", "-warn", "0", a_file, b_file], capture_output=True).returncode == 0
                    else:
                        equal = decoded(a_file) == decoded(b_file)
                    if not equal:
                        same[c["name"]] = False
    rows = []
    print(f"{'case':<40} {'A wall s':>15} {'B wall s':>15} {'B/A min':>8} {'B/A med':>8} {'write A->B s':>14} "
          f"{'trace A->B s':>14} {'bytes B/A':>9} pixels")
    for c in cases:
        a, b = runs[c["name"]]["a"], runs[c["name"]]["b"]
        wa, wb = [x["wall"] for x in a], [x["wall"] for x in b]
        row = {"case": c["name"], "threads": int(c["threads"]), "a_wall_min": min(wa), "a_wall_median": statistics.median(wa),
               "b_wall_min": min(wb), "b_wall_median": statistics.median(wb),
               "b_over_a_min": min(wb) / min(wa), "b_over_a_median": statistics.median(wb) / statistics.median(wa),
               "a_write_min": min(x["write"] for x in a), "b_write_min": min(x["write"] for x in b),
               "a_trace_min": min(x["trace"] for x in a), "b_trace_min": min(x["trace"] for x in b),
               "a_bytes": a[0]["bytes"], "b_bytes": b[0]["bytes"], "same_pixels": same[c["name"]]}
        rows.append(row)
        print(f"{c['name']:<40} {row['a_wall_min']:7.3f}/{row['a_wall_median']:7.3f} {row['b_wall_min']:7.3f}/{row['b_wall_median']:7.3f} "
              f"{row['b_over_a_min']:8.3f} {row['b_over_a_median']:8.3f} {row['a_write_min']:6.3f}->{row['b_write_min']:6.3f} "
              f"{row['a_trace_min']:6.3f}->{row['b_trace_min']:6.3f} {row['b_bytes'] / row['a_bytes']:9.3f} "
              f"{'same' if row['same_pixels'] else 'DIFFER'}")
    results = args.results or tempfile.mkdtemp(prefix="orbit_wall_results.")
    os.makedirs(results, exist_ok=True)
    path = os.path.join(results, "orbit_wall.json")
    with open(path, "w") as f:
        json.dump({"a": args.a, "b": args.b, "rounds": args.rounds, "orbit": args.orbit, "aovs": args.aovs, "rows": rows}, f, indent=1)
    print("wrote", path)
    return 0 if all(same.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
