#!/usr/bin/python3
"""octiso-view in headless Chromium: latency from an isovalue change to the new frame in the
browser (issue 20), the page's own measurement (window.octiso.lastFrame): latencyMs is fetch sent
until the frame is drawable (raw RGBA wrapped as ImageData, or a PNG decoded) and put on the
canvas; shownMs is the next animation frame, the one that paints it. Companion of `octiso-bench
interactive`, which measures the same server with a C++ client; this one includes the browser.

    bench/interactive_browser.py --tools build [--sizes 512,1024] [--changes N] [--threads 2]
                                 [--encodings rgba[,png]] [--gesture release|nudge] [--gap-ms MS]
                                 [--quick] [--results DIR]

ch2better (/usr/share/mricron/templates/ch2better.nii.gz, converted with octiso-convert) at
isovalues 80.5 +- a few slider positions, the default three-quarter view, the viewport set to each
size exactly (DevTools device metrics). Each change is one slider release (a 'change' event: the
page asks for the full frame at once; --gesture nudge sends 'input' first, as a keyboard step
does); the next change is made --gap-ms (100) after that frame is painted. With two encodings the changes
alternate between them (an A/B in one run, under the same load). Per-phase timers: the server's
(wait behind another render, encode, whole handler) and the page's (headers received, drawable),
p50 and p95, and the CPU time octiso-view and Chromium took per frame. Writes
DIR/interactive_browser.json (default $TMPDIR/octiso-bench-results)."""
import argparse
import json
import math
import os
import select
import shutil
import subprocess
import sys
import tempfile
import time


# Per-phase timers of one frame: the server's (X-Octiso-Stats) and the page's (lastFrame.phases).
kPhases = ("server wait", "server encode", "server handler", "page headers", "page drawable")


def percentile(values, p):
    """The nearest-rank percentile, as octiso-bench interactive computes it."""
    v = sorted(values)
    return v[max(0, min(len(v) - 1, math.ceil(p * len(v)) - 1))]


def descendants(pid):
    """pid and every process below it (chromedriver -> chromium's browser, renderer, GPU ...)."""
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(ppid, []).append(int(entry))
    out, todo = [], [pid]
    while todo:
        p = todo.pop()
        out.append(p)
        todo += children.get(p, [])
    return out


def cpu_seconds(pids):
    """User + system CPU seconds of the live processes in pids (threads included)."""
    total = 0
    for pid in pids:
        try:
            with open(f"/proc/{pid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            total += (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
        except (OSError, IndexError, ValueError):
            pass
    return total


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tools", required=True)
    ap.add_argument("--sizes", default="512,1024")
    ap.add_argument("--changes", type=int)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--results", default=os.path.join(tempfile.gettempdir(), "octiso-bench-results"))
    ap.add_argument("--volume", default="/usr/share/mricron/templates/ch2better.nii.gz")
    ap.add_argument("--iso", type=float, default=80.5)
    ap.add_argument("--encodings", default="rgba",
                    help="the page's frame encodings, comma-separated (rgba: its loopback default; png); "
                         "more than one alternates them change by change")
    ap.add_argument("--gesture", choices=("release", "nudge"), default="release",
                    help="release: a 'change' alone (the slider let go); nudge: 'input' then 'change' in one "
                         "task, as a keyboard step on the slider fires them")
    ap.add_argument("--gap-ms", type=float, default=100,
                    help="idle time between a frame painted and the next change (default 100: a person "
                         "does not release the slider twice within a paint; 0 makes Chromium's compositing "
                         "of one frame overlap the next frame's render)")
    a = ap.parse_args()
    encodings = a.encodings.split(",")
    if not encodings or any(e not in ("rgba", "png") for e in encodings):
        ap.error("--encodings: rgba and/or png")
    changes = a.changes or (4 if a.quick else 60)
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.support.ui import WebDriverWait

    work = tempfile.mkdtemp(prefix="octiso_bench_browser_")
    viewer = driver = None
    rows = []
    try:
        oct_path = os.path.join(work, "volume.oct")
        subprocess.run([f"{a.tools}/octiso-convert", a.volume, "-o", oct_path], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        viewer = subprocess.Popen([f"{a.tools}/octiso-view", oct_path, "--port", "0", "--threads", str(a.threads),
                                   "--iso", repr(a.iso)], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        if not select.select([viewer.stdout], [], [], 30)[0]:
            raise RuntimeError("octiso-view printed no URL")
        url = viewer.stdout.readline().split(" at ")[-1].strip()
        options = webdriver.ChromeOptions()
        for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     "--window-size=1200,1200", "--force-device-scale-factor=1"):
            options.add_argument(flag)
        driver = webdriver.Chrome(service=Service(executable_path=shutil.which("chromedriver")), options=options)
        chromium_pid = driver.service.process.pid
        for side in [int(s) for s in a.sizes.split(",")]:
            driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                                   {"width": side, "height": side, "deviceScaleFactor": 1, "mobile": False})
            driver.get(url)
            wait = WebDriverWait(driver, 120)
            wait.until(lambda d: d.execute_script("return window.octiso.settled"))
            driver.set_script_timeout(120)
            start = driver.execute_script("return Number(document.getElementById('iso').value)")
            samples = {e: {"latency": [], "render": [], "shown": [], **{k: [] for k in kPhases}} for e in encodings}
            cpu_before = (cpu_seconds([viewer.pid]), cpu_seconds(descendants(chromium_pid)))
            wall_start = time.monotonic()
            # Changes alternate between the encodings (A/B in one run, same load), each encoding
            # seeing the same isovalues: change k of every encoding is slider position k.
            for i in range(-2 * len(encodings), changes * len(encodings)):   # two warm-up changes each
                encoding, k = encodings[i % len(encodings)], i // len(encodings)
                # One asynchronous script per change, answered from the page's own hook at the
                # animation frame that paints the new full frame: WebDriver does not poll the page
                # (each poll would run in Chromium while octiso-view renders on the same 2 cores).
                frame = driver.execute_async_script("""
                    const [position, encoding, gesture, done] = arguments;
                    const before = window.octiso.lastFrame.seq;
                    window.octiso.onShown = (f) => {
                      if (!(window.octiso.settled && f.full && f.seq > before)) return;
                      window.octiso.onShown = null;
                      const s = f.stats, p = f.phases;
                      done([f.encoding, f.width, f.height, f.latencyMs, s.seconds * 1e3, f.shownMs, s.wait * 1e3,
                            s.encode * 1e3, s.server * 1e3, p.headers, p.decoded]);
                    };
                    window.octiso.encoding = encoding;
                    const s = document.getElementById('iso');
                    s.value = String(position);
                    if (gesture === 'nudge') s.dispatchEvent(new Event('input'));
                    s.dispatchEvent(new Event('change'));""", start + (k + 2) % 20 - 10, encoding, a.gesture)   # a drag of 20 slider positions
                assert frame[:3] == [encoding, side, side], frame
                time.sleep(a.gap_ms / 1e3)   # the paint of this frame ends before the next change
                if k >= 0:
                    for name, v in zip(("latency", "render", "shown") + kPhases, frame[3:]):
                        samples[encoding][name].append(v)
            wall = time.monotonic() - wall_start
            n_frames = (changes + 2) * len(encodings)
            cpu = {"viewer_cpu_ms_per_frame": (cpu_seconds([viewer.pid]) - cpu_before[0]) / n_frames * 1e3,
                   "chromium_cpu_ms_per_frame": (cpu_seconds(descendants(chromium_pid)) - cpu_before[1]) / n_frames * 1e3,
                   "wall_ms_per_frame": wall / n_frames * 1e3}
            for encoding in encodings:
                m = samples[encoding]
                row = {"image": side, "encoding": encoding, "changes": changes,
                       "p50_ms": percentile(m["latency"], 0.5), "p95_ms": percentile(m["latency"], 0.95),
                       "max_ms": max(m["latency"]),
                       "shown_p50_ms": percentile(m["shown"], 0.5), "shown_p95_ms": percentile(m["shown"], 0.95),
                       "render_p50_ms": percentile(m["render"], 0.5), "render_p95_ms": percentile(m["render"], 0.95),
                       "phases_p50_ms": {k: percentile(m[k], 0.5) for k in kPhases},
                       "phases_p95_ms": {k: percentile(m[k], 0.95) for k in kPhases}, **cpu}
                rows.append(row)
                print(f"{side}^2 {encoding}: isovalue change -> frame drawable in Chromium: p50 {row['p50_ms']:.1f} ms, "
                      f"p95 {row['p95_ms']:.1f} ms, max {row['max_ms']:.1f} ms; painted (next animation frame) p50 "
                      f"{row['shown_p50_ms']:.1f} ms, p95 {row['shown_p95_ms']:.1f} ms; render alone p50 "
                      f"{row['render_p50_ms']:.1f} ms, p95 {row['render_p95_ms']:.1f} ms ({changes} changes)")
                print("  phases p50 / p95 ms (server: wait behind another render, encode, whole handler;"
                      " page: since fetch sent):")
                for k in kPhases:
                    print(f"    {k:>15}: {row['phases_p50_ms'][k]:7.1f} / {row['phases_p95_ms'][k]:7.1f}")
            print(f"  CPU per frame (both encodings): octiso-view {cpu['viewer_cpu_ms_per_frame']:.1f} ms, "
                  f"Chromium and chromedriver {cpu['chromium_cpu_ms_per_frame']:.1f} ms, wall {cpu['wall_ms_per_frame']:.1f} ms")
    finally:
        if driver is not None:
            driver.quit()
        if viewer is not None:
            viewer.terminate()
            viewer.wait(10)
        shutil.rmtree(work, ignore_errors=True)
    with open("/proc/loadavg") as f:
        load = float(f.read().split()[0])
    os.makedirs(a.results, exist_ok=True)
    path = os.path.join(a.results, "interactive_browser.json")
    with open(path, "w") as f:
        json.dump({"volume": a.volume, "iso": a.iso, "threads": a.threads, "gesture": a.gesture, "gap_ms": a.gap_ms,
                   "load_average_1min": load,
                   "browser": "headless chromium", "rows": rows}, f, indent=1)
    print(f"wrote {path} (load average {load})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
