#!/usr/bin/python3
"""The cost of octiso-render's progress line inside a frame (issue 17 item 5): the same frame rendered
with and without --progress (tiles in batches of about 0.25 s through Renderer::render_tiles, the line
redrawn between them, against one render()), PAIRS times, A and B interleaved and the order flipped
every pair so that drift on a shared machine hits both alike. Prints the medians of the tile loop
(`seconds`) and the whole frame (`frame_seconds`, incl. shading) from --json, and checks that both
images are the same bytes (BENCHMARKS.md, "Progress inside a frame").

    scripts/progress_cost.py [--render build/octiso-render] [--size 2048x2048] [--pairs 8] [--threads 2]
                             [--flags '--iso 80.5'] FILE.oct"""
import argparse
import json
import statistics
import subprocess
import tempfile


def main():
    p = argparse.ArgumentParser()
    p.add_argument("file")
    p.add_argument("--render", default="build/octiso-render")
    p.add_argument("--size", default="2048x2048")
    p.add_argument("--pairs", type=int, default=8)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--flags", default="--iso 80.5")
    a = p.parse_args()
    runs = {"off": [], "on": []}
    with tempfile.TemporaryDirectory() as tmp:
        def render(mode):
            extra = ["--progress"] if mode == "on" else []
            out = subprocess.run([a.render, a.file, *a.flags.split(), "--size", a.size, "--threads", str(a.threads), *extra,
                                  "-o", f"{tmp}/{mode}.png", "--json"], check=True, capture_output=True, text=True).stdout
            runs[mode].append(json.loads(out)["frames"][0])
        for i in range(a.pairs):
            for mode in (("off", "on") if i % 2 == 0 else ("on", "off")):
                render(mode)
        same = open(f"{tmp}/on.png", "rb").read() == open(f"{tmp}/off.png", "rb").read()
    print(f"{a.file} {a.flags} --size {a.size} --threads {a.threads}, {a.pairs} interleaved pairs; images identical: {same}")
    print("| progress | tile loop s (median) | whole frame s (median) | min frame s | max frame s |")
    print("|---|---|---|---|---|")
    med = {}
    for mode in ("off", "on"):
        tile = statistics.median(r["seconds"] for r in runs[mode])
        frame = [r["frame_seconds"] for r in runs[mode]]
        med[mode] = statistics.median(frame)
        print(f"| {mode} | {tile:.4f} | {med[mode]:.4f} | {min(frame):.4f} | {max(frame):.4f} |")
    print(f"on / off (median whole frame): {med['on'] / med['off']:.4f}")
    if not same:
        raise SystemExit("images differ")


if __name__ == "__main__":
    main()
