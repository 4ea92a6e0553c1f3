"""Scaling plot: left, measured parallel efficiency per thread count and image size (with the tile
loop's utilisation, issue 12) and, where the run built the octree, the build's efficiency; right,
the simulated speedup of the dynamic tile schedule (and a static split) from measured tile costs,
and the model that adds the measured serial per-frame time and machine ceiling (all simulated)."""
import matplotlib.pyplot as plt


def plot(data, out_png):
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    # One line per image size and tile order (issue 12: --tile-order both measures split and sweep).
    groups = sorted({(m["width"], m.get("tile_order", "split")) for m in data["measured"]})
    several_orders = len({order for _, order in groups}) > 1
    for w, order in groups:
        rows = sorted((m for m in data["measured"] if m["width"] == w and m.get("tile_order", "split") == order),
                      key=lambda m: m["threads"])
        one = next(m["median_seconds"] for m in rows if m["threads"] == 1)
        p = [m["threads"] for m in rows]
        eff = [100.0 * one / m["median_seconds"] / m["threads"] for m in rows]
        tag = f"{w}^2 {order}" if several_orders else f"{w}^2"
        left.plot(p, eff, "o-", label=f"{tag} wall")
        if all(m.get("busy_seconds") for m in rows):
            med = lambda v: sorted(v)[len(v) // 2]
            left.plot(p, [100.0 * med(m["busy_seconds"]) / (m["threads"] * m["median_seconds"]) for m in rows], "^:",
                      label=f"{tag} tile-loop utilisation")
        if all(m.get("cpu_seconds") for m in rows):
            med = lambda v: sorted(v)[len(v) // 2]
            one_cpu = med(next(m["cpu_seconds"] for m in rows if m["threads"] == 1))
            left.plot(p, [100.0 * one_cpu / med(m["cpu_seconds"]) for m in rows], "s--",
                      label=f"{tag} CPU work (1 thread / P threads)")
    builds = sorted(data.get("build", []), key=lambda b: b["threads"])
    if builds:
        one = next(b["median_seconds"] for b in builds if b["threads"] == 1)
        left.plot([b["threads"] for b in builds], [100.0 * one / b["median_seconds"] / b["threads"] for b in builds],
                  "v-", color="black", label="build (in memory)")
    left.axhline(95, color="grey", ls="--", lw=0.8, label="target 95 % at 2 threads (issue 5)")
    left.axhline(90, color="grey", ls=":", lw=0.8, label="target 90 % at 16 threads (issue 12)")
    left.set_xlabel("threads")
    left.set_ylabel("parallel efficiency, %")
    left.set_ylim(0, 110)
    left.set_title("measured (render(), Embree, colour)")
    left.legend(fontsize=8)
    left.grid(alpha=0.3)
    for s in data["simulated"]:
        right.plot(s["workers"], s["dynamic_speedup"], "o-", label=f"dynamic {s['width']}^2, {s.get('tile', 16)}^2 tiles")
        if s.get("model_speedup"):
            right.plot(s["workers"], s["model_speedup"], "d--",
                       label=f"+ serial + ceiling {s['width']}^2, {s.get('tile', 16)}^2 tiles")
        if s.get("tile", 16) == 16:
            right.plot(s["workers"], s["static_speedup"], "x:", label=f"static {s['width']}^2, {s.get('tile', 16)}^2 tiles")
    top = max(max(s["workers"]) for s in data["simulated"])
    right.plot([1, top], [1, top], color="grey", lw=0.8, label="ideal")
    right.plot([1, top], [0.9, 0.9 * top], color="grey", ls="--", lw=0.8, label="90 % efficiency")
    right.set_xscale("log", base=2)
    right.set_yscale("log", base=2)
    right.set_xlabel("workers")
    right.set_ylabel("speedup (sum of tile costs / makespan)")
    right.set_title("SIMULATED schedule of measured tile costs")
    right.legend(fontsize=7)
    right.grid(alpha=0.3)
    fig.suptitle(f"{data['dataset']} {'x'.join(map(str, data['dims']))}, iso {data['iso']}; "
                 f"load average {data.get('loadavg', '?').split(' ')[0]} on this machine", fontsize=10)
    fig.tight_layout()
    fig.savefig(out_png, dpi=120)
