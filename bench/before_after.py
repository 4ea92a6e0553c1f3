#!/usr/bin/python3
"""Issue 11's target ">= 2.5 x faster than before the issue", measured directly: the pre-issue
octiso-render (commit 0102e1b, its default: Embree rtcIntersect8 with each lane traced alone)
against this build's default, interleaved, one process per frame, default three-quarter camera,
512^2, 1 thread, depth only; min of 7 rounds. Prints a line per case, writes JSON, and exits 1
when the two disagree on the hit count (then they did not render the same view of the same data).

The pre-issue tools come from a worktree of that commit and read only the .oct files of their own
converter (format 2):
    git worktree add /tmp/old 0102e1b && cmake -S /tmp/old -B /tmp/old/build -DCMAKE_BUILD_TYPE=Release
    make -C /tmp/old/build -j2 octiso-render octiso-convert
    /tmp/old/build/octiso-convert /usr/share/mricron/templates/ch2better.nii.gz -o old_ch2better.oct
    build/octiso-convert /usr/share/mricron/templates/ch2better.nii.gz -o ch2better.oct
    /usr/bin/python3 bench/before_after.py /tmp/old/build/octiso-render build/octiso-render OUT.json \\
        old_ch2better.oct,ch2better.oct@100.5 [...]
The old tool has no orbit, so both sides pay a process's first frame."""
import json
import os
import subprocess
import sys
import tempfile

ROUNDS = 7


def frame(binary, oct_file, iso, depth, new):
    out = subprocess.run([binary, oct_file, "--iso", iso, "--threads", "1", "--depth", depth, "--json"],
                         capture_output=True, text=True, check=True).stdout
    f = json.loads(out)["frames"][0]
    # The old report has one time, the whole render() call; the new one splits it into phases.
    return (f["frame_seconds"], f["phases"]["trace"], f["hits"]) if new else (f["seconds"], None, f["hits"])


def main():
    old_bin, new_bin, out_json = sys.argv[1:4]
    rows, agree = [], True
    with tempfile.TemporaryDirectory() as tmp:
        depth = os.path.join(tmp, "depth.exr")
        for case in sys.argv[4:]:
            files, iso = case.rsplit("@", 1)
            old_oct, new_oct = files.split(",")
            old_s, new_s, new_trace, hits = [], [], [], set()
            for r in range(ROUNDS):
                for who in (("old", "new") if r % 2 == 0 else ("new", "old")):
                    if who == "old":
                        s, _, h = frame(old_bin, old_oct, iso, depth, False)
                        old_s.append(s)
                    else:
                        s, t, h = frame(new_bin, new_oct, iso, depth, True)
                        new_s.append(s), new_trace.append(t)
                    hits.add(h)
            agree &= len(hits) == 1
            row = dict(file=os.path.basename(new_oct), iso=float(iso), hits=sorted(hits), old_min_s=min(old_s),
                       new_frame_min_s=min(new_s), new_trace_min_s=min(new_trace), speedup_frame=min(old_s) / min(new_s),
                       speedup_trace=min(old_s) / min(new_trace), old_s=old_s, new_frame_s=new_s, new_trace_s=new_trace)
            rows.append(row)
            print(f"{row['file']} @{iso}: before {min(old_s) * 1e3:.1f} ms, now {min(new_s) * 1e3:.1f} ms "
                  f"(trace {min(new_trace) * 1e3:.1f}): {row['speedup_frame']:.2f} x ({row['speedup_trace']:.2f} x on the "
                  f"trace); hits {sorted(hits)}", flush=True)
    with open(out_json, "w") as f:
        json.dump(dict(description=__doc__.split("\n\n")[0], old_binary=old_bin, new_binary=new_bin, rounds=ROUNDS,
                       rows=rows), f, indent=1)
    print(f"wrote {out_json}")
    if not agree:
        print("before_after.py: the two builds disagree on a hit count", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
