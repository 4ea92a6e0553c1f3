#!/usr/bin/python3
"""octiso-view in headless Chromium: latency from an isovalue change to the new frame decoded in
the browser (issue 20), the page's own measurement (window.octiso.lastFrame.latencyMs: fetch sent
until the PNG is decoded by the browser, before paint). Companion of `octiso-bench interactive`,
which measures the same server with a C++ client; this one includes the browser's fetch and decode.

    bench/interactive_browser.py --tools build [--sizes 512,1024] [--changes N] [--threads 2]
                                 [--quick] [--results DIR]

ch2better (/usr/share/mricron/templates/ch2better.nii.gz, converted with octiso-convert) at
isovalues 80.5 +- a few slider positions, the default three-quarter view, the viewport set to each
size exactly (DevTools device metrics). Each change is one slider release (a 'change' event: the
page asks for the full frame at once); the next change is made when that frame is shown. Writes
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


def percentile(values, p):
    """The nearest-rank percentile, as octiso-bench interactive computes it."""
    v = sorted(values)
    return v[max(0, min(len(v) - 1, math.ceil(p * len(v)) - 1))]


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
    a = ap.parse_args()
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
        for side in [int(s) for s in a.sizes.split(",")]:
            driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                                   {"width": side, "height": side, "deviceScaleFactor": 1, "mobile": False})
            driver.get(url)
            wait = WebDriverWait(driver, 120)
            wait.until(lambda d: d.execute_script("return window.octiso.settled"))
            start = driver.execute_script("return Number(document.getElementById('iso').value)")
            latencies, renders = [], []
            for i in range(-2, changes):   # two warm-up changes
                seq = driver.execute_script("""
                    const s = document.getElementById('iso');
                    s.value = String(arguments[0]);
                    s.dispatchEvent(new Event('change'));
                    return window.octiso.lastFrame.seq;""", start + (i + 2) % 20 - 10)   # a drag of 20 slider positions
                wait.until(lambda d: d.execute_script(
                    "return window.octiso.settled && window.octiso.lastFrame.seq > arguments[0]", seq))
                frame = driver.execute_script("const f = window.octiso.lastFrame; return [f.latencyMs, f.width, f.height, f.stats.seconds];")
                assert frame[1] == side and frame[2] == side, frame
                if i >= 0:
                    latencies.append(frame[0])
                    renders.append(frame[3] * 1e3)
            rows.append({"image": side, "changes": changes, "p50_ms": percentile(latencies, 0.5),
                         "p95_ms": percentile(latencies, 0.95), "max_ms": max(latencies),
                         "render_p50_ms": percentile(renders, 0.5)})
            print(f"{side}^2: isovalue change -> frame decoded in Chromium: p50 {rows[-1]['p50_ms']:.1f} ms, "
                  f"p95 {rows[-1]['p95_ms']:.1f} ms, max {rows[-1]['max_ms']:.1f} ms, render alone p50 "
                  f"{rows[-1]['render_p50_ms']:.1f} ms ({changes} changes)")
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
        json.dump({"volume": a.volume, "iso": a.iso, "threads": a.threads, "load_average_1min": load,
                   "browser": "headless chromium", "rows": rows}, f, indent=1)
    print(f"wrote {path} (load average {load})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
