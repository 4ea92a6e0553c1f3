#!/usr/bin/python3
"""The frame-time cost of one octiso-render flag: the same frame rendered without FLAG (A) and with it
(B), PAIRS times, A and B interleaved and the order flipped every pair so that drift on a shared
machine hits both alike. Prints the medians of the tile loop (`seconds`) and the whole frame
(`frame_seconds`, incl. shading and any pass after tracing) from --json. With --same-image it also
checks that both images are the same bytes (a flag that must not change the image, e.g. --progress).

    scripts/flag_cost.py [--render build/octiso-render] [--size 2048x2048] [--pairs 8] [--threads 2]
                         [--flags '--iso 80.5'] [--flag --progress] [--same-image] FILE.oct

Used for BENCHMARKS.md, "Progress inside a frame" (--flag --progress --same-image) and
"Ray-traced look" (--flag --clip-cap)."""
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
    p.add_argument("--flag", default="--progress")
    p.add_argument("--same-image", action="store_true")
    a = p.parse_args()
    runs = {"without": [], "with": []}
    with tempfile.TemporaryDirectory() as tmp:
        def render(mode):
            extra = a.flag.split() if mode == "with" else []
            out = subprocess.run([a.render, a.file, *a.flags.split(), "--size", a.size, "--threads", str(a.threads), *extra,
                                  "-o", f"{tmp}/{mode}.png", "--json"], check=True, capture_output=True, text=True).stdout
            runs[mode].append(json.loads(out)["frames"][0])
        for i in range(a.pairs):
            for mode in (("without", "with") if i % 2 == 0 else ("with", "without")):
                render(mode)
        same = open(f"{tmp}/with.png", "rb").read() == open(f"{tmp}/without.png", "rb").read()
    print(f"{a.file} {a.flags} --size {a.size} --threads {a.threads}, {a.flag} or not, {a.pairs} interleaved pairs; "
          f"images identical: {same}")
    print(f"| {a.flag} | tile loop s (median) | whole frame s (median) | min frame s | max frame s |")
    print("|---|---|---|---|---|")
    med = {}
    for mode in ("without", "with"):
        tile = statistics.median(r["seconds"] for r in runs[mode])
        frame = [r["frame_seconds"] for r in runs[mode]]
        med[mode] = statistics.median(frame)
        print(f"| {mode} | {tile:.4f} | {med[mode]:.4f} | {min(frame):.4f} | {max(frame):.4f} |")
    print(f"with / without (median whole frame): {med['with'] / med['without']:.4f}")
    if a.same_image and not same:
        raise SystemExit("images differ")


if __name__ == "__main__":
    main()
