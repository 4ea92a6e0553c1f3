"""Error against run time for `octiso-bench lod`: one line per case (dataset, isovalue, image,
view) through its factors F (0 = exact, at speed-up 1), speed-up over the exact frame on x and,
in three panels, the hit-mask mismatch, the p99 depth error and the share of the file touched.
A point up and to the left of another is dominated: the Pareto front runs right and low."""
import matplotlib.pyplot as plt


def plot(data, out_png):
    cases = data["cases"]
    if not cases:
        return
    series = {}
    for c in cases:
        key = f'{c["dataset"]} @{c["iso"]:g}, {c["image"]}^2, {c["view"]}'
        series.setdefault(key, []).append(c)
    fig, axes = plt.subplots(1, 3, figsize=(16, 5.5))
    panels = [("mismatch", 100.0, "hit-mask mismatch, % of exact hits"),
              ("depth_error_p99", 1.0, "depth error p99, voxels"),
              ("touched", 100.0, "file touched by one frame, %")]
    for ax, (field, scale, label) in zip(axes, panels):
        for key, rows in series.items():
            rows = sorted(rows, key=lambda r: r["lod"])
            xs = [r["speedup"] for r in rows]
            if field == "touched":
                ys = [scale * r["touched_bytes"] / r["file_bytes"] for r in rows]
            else:
                ys = [scale * r[field] for r in rows]
            style = "-o" if rows[0]["view"] == "whole" else "--s"
            ax.plot(xs, ys, style, label=key, markersize=4)
            for r, x, y in zip(rows, xs, ys):
                ax.annotate(f'{r["lod"]:g}', (x, y), fontsize=6, xytext=(2, 2), textcoords="offset points")
        ax.set_xlabel("speed-up over the exact frame (labels: F)")
        ax.set_ylabel(label)
        if field != "touched":
            ax.set_yscale("symlog", linthresh=1e-3 if field == "mismatch" else 1e-2)
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=6)
    fig.suptitle("octiso --lod F: error against run time (" + data.get("machine", "") + ")", fontsize=9)
    fig.tight_layout()
    fig.savefig(out_png, dpi=110)
