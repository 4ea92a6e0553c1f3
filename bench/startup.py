#!/usr/bin/python3
"""Start-up time of octiso's programs: what every tool run and every ctest case pays before it
does any work (the dynamic loader, static constructors).

    bench/startup.py --tools BUILD_DIR [--tools OTHER_DIR ...] [--program NAME=PATH ...]
                     [--render FILE.oct@ISO ...] [--runs 15] [--results DIR]

Each build directory contributes `octiso-render --help`, `octiso-convert --help` and
`octiso_tests --gtest_filter=None.None` (the start of one of the ~680 processes ctest runs); each
--program another `PATH --help` (e.g. an older octiso-render kept for comparison). --render adds,
for every octiso-render above, the whole process of one default frame of FILE.oct at ISO written
as a PNG (`-o frame.png --threads 1`): what a script that renders one image per call pays. The commands
are run in rounds, each round every command once (interleaved, so load drift hits all alike);
the table gives min and median wall seconds and the shared libraries `ldd` lists. Writes
startup.json into --results only when asked (default: a temporary folder, printed).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time


def library_count(path):
    out = subprocess.run(["ldd", path], capture_output=True, text=True).stdout
    return sum(1 for line in out.splitlines() if ".so" in line)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tools", action="append", default=[], help="a build directory (repeatable)")
    ap.add_argument("--program", action="append", default=[], help="NAME=PATH of another program to time with --help")
    ap.add_argument("--render", action="append", default=[], help="FILE.oct@ISO: also time one PNG frame of it (repeatable)")
    ap.add_argument("--runs", type=int, default=15)
    ap.add_argument("--results", help="folder for startup.json (default: a temporary folder)")
    args = ap.parse_args()
    if not args.tools and not args.program:
        ap.error("give at least one --tools or --program")

    commands = []   # (name, argv)
    for d in args.tools:
        tag = os.path.basename(os.path.normpath(d))
        for tool in ("octiso-render", "octiso-convert"):
            commands.append((f"{tag}/{tool} --help", [os.path.join(d, tool), "--help"]))
        commands.append((f"{tag}/octiso_tests (one empty case)", [os.path.join(d, "octiso_tests"), "--gtest_filter=None.None"]))
    renderers = [(os.path.basename(os.path.normpath(d)) + "/octiso-render", os.path.join(d, "octiso-render")) for d in args.tools]
    for p in args.program:
        name, _, path = p.partition("=")
        commands.append((f"{name} --help", [path, "--help"]))
        if "octiso-render" in os.path.basename(path):
            renderers.append((name, path))
    frame_dir = tempfile.mkdtemp(prefix="octiso-startup-frame-")
    for spec in args.render:
        oct_file, _, iso = spec.rpartition("@")
        if not oct_file or not os.path.isfile(oct_file):
            sys.exit(f"startup.py: --render {spec}: expected an existing FILE.oct@ISO")
        for name, path in renderers:
            commands.append((f"{name} {os.path.basename(oct_file)} -o frame.png",
                             [path, oct_file, "--iso", iso, "--threads", "1", "-o", os.path.join(frame_dir, "frame.png")]))
    for name, argv in commands:
        if not os.access(argv[0], os.X_OK):
            sys.exit(f"startup.py: {argv[0]}: not an executable")

    env = dict(os.environ)
    env.setdefault("LSAN_OPTIONS", "suppressions=" + os.path.join(os.path.dirname(__file__), "..", "scripts", "lsan.supp"))
    seconds = {name: [] for name, _ in commands}
    for _ in range(args.runs):
        for name, argv in commands:
            t0 = time.perf_counter()
            subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, check=True)
            seconds[name].append(time.perf_counter() - t0)

    rows = []
    print(f"{'program':76} {'min s':>8} {'median s':>9} {'libraries':>9}")
    for name, argv in commands:
        s = seconds[name]
        row = {"program": name, "path": argv[0], "min_seconds": min(s), "median_seconds": statistics.median(s),
               "libraries": library_count(argv[0]), "seconds": s}
        rows.append(row)
        print(f"{name:76} {row['min_seconds']:8.3f} {row['median_seconds']:9.3f} {row['libraries']:9d}")

    out_dir = args.results or tempfile.mkdtemp(prefix="octiso-startup-")
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, "startup.json")
    with open(path, "w") as f:
        json.dump({"bench": "startup", "runs": args.runs, "date": time.strftime("%Y-%m-%d"),
                   "machine": f"{os.cpu_count()} hardware threads", "rows": rows}, f, indent=1)
    print(f"JSON: {path}")


if __name__ == "__main__":
    main()
