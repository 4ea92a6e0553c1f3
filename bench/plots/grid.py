"""Grid plot (the paper's Table 3): frames/s per dataset for the macrocell grid and the octree, each
over array data and octree data; the best grid configuration per data source is drawn."""
import matplotlib.pyplot as plt


def plot(data, out_png):
    runs = data["datasets"]
    kinds = [("grid", "array"), ("grid", "octree"), ("octree", "array"), ("octree", "octree")]
    fig, ax = plt.subplots(figsize=(max(6.0, 2.2 * len(runs) + 1.5), 4.5))
    width = 0.2
    for k, (structure, source) in enumerate(kinds):
        values, labels = [], []
        for run in runs:
            best = max((v for v in run["variants"] if v["structure"] == structure and v["data"] == source),
                       key=lambda v: v["fps"], default=None)
            values.append(best["fps"] if best else 0.0)
            labels.append(best["grid"] if best and best["grid"] else "")
        xs = [i + (k - 1.5) * width for i in range(len(runs))]
        bars = ax.bar(xs, values, width, label=f"{structure} over {source} data")
        for b, lab in zip(bars, labels):
            text = f"{b.get_height():.1f}" + (f"\n{lab}" if lab else "")
            ax.annotate(text, (b.get_x() + b.get_width() / 2, b.get_height()), ha="center", va="bottom", fontsize=6)
    ax.set_xticks(range(len(runs)))
    ax.set_xticklabels([f"{r['name']} {'x'.join(map(str, r['dims']))}\noctree/grid = {r['ratio_octree_octree_vs_grid_array']:.2f}"
                        for r in runs], fontsize=8)
    ax.set_ylabel("frames/s")
    ax.set_title(f"Macrocell grid vs octree, {data['width']}x{data['height']}, {data['threads']} threads")
    ax.legend(fontsize=7)
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out_png, dpi=120)
