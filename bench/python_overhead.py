#!/usr/bin/python3
"""What the Python module adds to the C++ library (issue 16 targets), interleaved in one run:

  build: octiso.build(array) on a dense u8 array vs the build time octiso-convert reports for the
         same voxels as a raw file (--json build_seconds: the build alone, reading excluded);
  frame: octiso.Renderer.render() wall time in Python vs the C++ tile loop inside it
         (Frame.seconds), at 512^2, and octiso-render's frame seconds for the same camera.

    bench/python_overhead.py --tools BUILD_DIR [--size 512] [--repeats 5] [--quick] [--results DIR]

Prints a table, writes python_overhead.json to DIR (default $TMPDIR/octiso-bench-results)."""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tools", required=True, help="build directory with the tools and python/octiso")
    p.add_argument("--size", type=int, default=512)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--quick", action="store_true", help="128^3, 2 repeats")
    p.add_argument("--results", default=os.path.join(tempfile.gettempdir(), "octiso-bench-results"))
    args = p.parse_args()
    if args.quick:
        args.size, args.repeats = 128, 2
    sys.path.insert(0, os.path.join(args.tools, "python"))
    import numpy as np
    import octiso

    n = args.size
    work = tempfile.mkdtemp(prefix="octiso_pybench_")
    oct_path, raw = os.path.join(work, "plume.oct"), os.path.join(work, "plume.raw")
    tool = lambda name: os.path.join(args.tools, name)  # noqa: E731
    subprocess.run([tool("octiso-convert"), "--synthetic", f"plume:{n}", "-o", oct_path], check=True, capture_output=True)
    subprocess.run([tool("octiso-info"), oct_path, "--extract-raw", raw], check=True, capture_output=True)
    volume = np.fromfile(raw, dtype=np.uint8).reshape(n, n, n)

    build_py, build_cli, frame_py_wall, frame_py_loop, frame_cli = [], [], [], [], []
    tree = None
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        tree = octiso.build(volume)
        build_py.append(time.perf_counter() - t0)
        out = subprocess.run([tool("octiso-convert"), raw, "--dims", f"{n},{n},{n}", "--type", "u8", "-o",
                              os.path.join(work, "cli.oct"), "--json"], check=True, capture_output=True, text=True)
        build_cli.append(json.loads(out.stdout)["build_seconds"])

    camera = octiso.Camera.frame(tree, size=(512, 512))
    renderer = octiso.Renderer(tree, 100.5, size=(512, 512))
    renderer.render(camera)   # warm
    eye, look = ",".join(map(str, camera.eye)), ",".join(map(str, camera.look))
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        frame = renderer.render(camera)
        frame_py_wall.append(time.perf_counter() - t0)
        frame_py_loop.append(frame.seconds)
        out = subprocess.run([tool("octiso-render"), oct_path, "--iso", "100.5", "--size", "512x512", "--eye", eye, "--look",
                              look, "--up", "0,0,1", "--fov", str(camera.fov), "--shading", "headlight", "-o", os.path.join(work, "f.png"), "--json"],
                             check=True, capture_output=True, text=True)
        frame_cli.append(json.loads(out.stdout)["frames"][0]["seconds"])

    med = statistics.median
    rows = {
        "build_python_s": med(build_py), "build_cli_s": med(build_cli),
        "build_ratio": med(build_py) / med(build_cli),
        "frame_python_wall_s": med(frame_py_wall), "frame_tile_loop_s": med(frame_py_loop),
        "frame_overhead_ms": (med(frame_py_wall) - med(frame_py_loop)) * 1e3,
        "frame_cli_s": med(frame_cli),
    }
    print(f"python overhead, plume {n}^3 u8, 512^2 frames, median of {args.repeats} interleaved repeats")
    print(f"  build   python {rows['build_python_s']:.3f} s   octiso-convert (build only) {rows['build_cli_s']:.3f} s"
          f"   ratio {rows['build_ratio']:.3f}   (target <= 1.05)")
    print(f"  frame   python wall {rows['frame_python_wall_s'] * 1e3:.2f} ms   C++ tile loop {rows['frame_tile_loop_s'] * 1e3:.2f} ms"
          f"   overhead {rows['frame_overhead_ms']:.2f} ms (target <= 1)   octiso-render {rows['frame_cli_s'] * 1e3:.2f} ms")
    os.makedirs(args.results, exist_ok=True)
    path = os.path.join(args.results, "python_overhead.json")
    with open(path, "w") as f:
        json.dump({"size": n, "repeats": args.repeats, "median": rows,
                   "samples": {"build_python_s": build_py, "build_cli_s": build_cli, "frame_python_wall_s": frame_py_wall,
                               "frame_tile_loop_s": frame_py_loop, "frame_cli_s": frame_cli}}, f, indent=1)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
