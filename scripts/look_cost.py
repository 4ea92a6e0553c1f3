#!/usr/bin/python3
"""The frame-time cost of each ray-traced look flag of octiso-render (issue 17 item 7): one FILE.oct,
one camera, each row rendered REPEAT times on THREADS threads, the fastest run kept (the least
disturbed by other work on a shared machine), printed as the markdown table of BENCHMARKS.md
("Ray-traced look").

    scripts/look_cost.py [--render build/octiso-render] [--size 512x512] [--repeat 5] [--threads 1] FILE.oct"""
import argparse
import json
import subprocess
import tempfile

ROWS = [
    ("light kit (no look)", "--iso 80.5"),
    ("--clip 1,0,0,10", "--iso 80.5 --clip 1,0,0,10"),
    ("--shadows", "--iso 80.5 --shadows"),
    ("--ao 8", "--iso 80.5 --ao 8"),
    ("--ao 16", "--iso 80.5 --ao 16"),
    ("--shadows --ao 16", "--iso 80.5 --shadows --ao 16"),
    ("--iso 60,105 (opaque)", "--iso 60,105"),
    ("--iso 60,105 --opacity 0.15", "--iso 60,105 --opacity 0.15"),
    ("--iso 60,105 --opacity 0.15 --shadows --clip 1,0,0,10", "--iso 60,105 --opacity 0.15 --shadows --clip 1,0,0,10"),
]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("file")
    p.add_argument("--render", default="build/octiso-render")
    p.add_argument("--size", default="512x512")
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--threads", type=int, default=1)
    a = p.parse_args()
    print(f"| flags ({a.file}, {a.size}, {a.threads} thread(s), best of {a.repeat}) | tile loop s | look s | whole frame s | x light kit | secondary rays | shadow | AO | past translucent | look Mrays/s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    base = None
    with tempfile.TemporaryDirectory() as tmp:
        for name, flags in ROWS:
            runs = []
            for _ in range(a.repeat):
                out = subprocess.run([a.render, a.file, *flags.split(), "--size", a.size, "--threads", str(a.threads), "-o", tmp + "/x.png", "--json"],
                                     check=True, capture_output=True, text=True).stdout
                runs.append(json.loads(out)["frames"][0])
            frame = min(r["frame_seconds"] for r in runs)
            tile = min(r["seconds"] for r in runs)
            sec = [r.get("secondary") for r in runs]
            look = min(s["seconds"] for s in sec) if sec[0] else 0.0
            s = sec[0] or {"shadow_rays": 0, "ao_rays": 0, "layer_rays": 0}
            rays = s["shadow_rays"] + s["ao_rays"] + s["layer_rays"]
            base = base or frame
            rate = f"{rays / look * 1e-6:.2f}" if look > 0 and rays else "-"
            print(f"| `{name}` | {tile:.3f} | {look:.3f} | {frame:.3f} | {frame / base:.2f} | {rays} | {s['shadow_rays']} | "
                  f"{s['ao_rays']} | {s['layer_rays']} | {rate} |")


if __name__ == "__main__":
    main()
