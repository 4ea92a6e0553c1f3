"""Root-finder Pareto plot: p99 position error (cell units) against ns per cell test, one panel for
the pooled recorded render streams and one for random cells; the Pareto front of the recorded
streams is drawn as a line, the default (neubauer 5) is ringed."""
import matplotlib.pyplot as plt

FLOOR = 1e-17   # exact has zero error against itself: drawn at the floor of the log axis


def _panel(ax, rows, title, front=None):
    for r in rows:
        x, y = r["ns_per_cell"], max(r["pos_p99"], FLOOR)
        colour = {"neubauer": "C0", "schwarze": "C1", "linear": "C2", "exact": "C3"}[r["finder"]]
        ax.scatter([x], [y], color=colour, s=28, zorder=3)
        if r.get("default"):
            ax.scatter([x], [y], facecolors="none", edgecolors="k", s=140, linewidths=1.5, zorder=4)
        label = r["label"].replace("neubauer ", "N=")
        if r["miss_pct"] > 0:
            label += f" (miss {r['miss_pct']:.2g}%)"
        ax.annotate(label, (x, y), textcoords="offset points", xytext=(4, 3), fontsize=7)
    if front:
        pts = sorted((r["ns_per_cell"], max(r["pos_p99"], FLOOR)) for r in rows if r["label"] in front)
        ax.plot([p[0] for p in pts], [p[1] for p in pts], "k--", lw=0.8, alpha=0.6, label="Pareto front")
        ax.legend(fontsize=7, loc="upper right")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("ns per cell test (first_root, cubic set-up included)")
    ax.set_ylabel("p99 position error (cell units)")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3, which="both")


def plot(data, out_png):
    front = {p["label"] for p in data["pareto"] if p["on_front"]}
    names = ", ".join(d["name"] for d in data["datasets"])
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    _panel(axes[0], data["pooled"], f"recorded render streams ({names})", front)
    _panel(axes[1], data["random"], f"random cells ({data['random_cells']})")
    fig.suptitle("Root finders: error against time (default ringed)", fontsize=10)
    fig.tight_layout()
    fig.savefig(out_png, dpi=120)
