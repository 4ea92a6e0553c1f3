"""Peers plot: per dataset, render time, time to first image after an isovalue change, and bytes of
each method (log scales; lower is better), with the hit-mask mismatch printed over each render bar."""
import math

import matplotlib.pyplot as plt
from matplotlib.patches import Patch


def _num(v):
    return v if isinstance(v, (int, float)) and v is not None and math.isfinite(v) else None


def plot(data, out_png):
    datasets = data["datasets"]
    methods = []
    for d in datasets:
        for m in d["methods"]:
            if m["method"] not in methods:
                methods.append(m["method"])
    panels = [("render_seconds", "render s (one frame)"), ("first_image_seconds", "first image after iso change, s"),
              ("bytes", "bytes (MB)")]
    fig, axes = plt.subplots(1, 3, figsize=(16, 6))
    width = 0.8 / max(len(methods), 1)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, (key, title) in zip(axes, panels):
        for mi, name in enumerate(methods):
            xs, ys, labels = [], [], []
            for di, d in enumerate(datasets):
                row = next((m for m in d["methods"] if m["method"] == name), None)
                v = _num(row.get(key)) if row else None
                if v is None or v <= 0:
                    continue
                if key == "bytes":
                    v = v / 1e6
                xs.append(di - 0.4 + width * (mi + 0.5))
                ys.append(v)
                err = row.get("error") if key == "render_seconds" else None
                labels.append(f"{100 * err['mask_mismatch_fraction']:.2g}%" if err else "")
            if not xs:
                continue
            bars = ax.bar(xs, ys, width, color=colours[mi % len(colours)])
            for b, text in zip(bars, labels):
                if text:
                    ax.annotate(text, (b.get_x() + b.get_width() / 2, b.get_height()), ha="center", va="bottom",
                                fontsize=6, rotation=90)
        ax.set_yscale("log")
        ax.margins(y=0.25)
        ax.set_xticks(range(len(datasets)))
        ax.set_xticklabels([f"{d['name']}\n{'x'.join(str(v) for v in d['dims'])}, iso {d['iso']}" for d in datasets],
                           fontsize=8)
        ax.set_title(title)
        ax.grid(axis="y", alpha=0.3, which="both")
    fig.legend(handles=[Patch(color=colours[i % len(colours)], label=m) for i, m in enumerate(methods)],
               loc="lower center", ncol=min(len(methods), 4), fontsize=8)
    fig.suptitle(f"octiso vs peers, {data['width']}x{data['height']} primary rays (labels: hit-mask mismatch "
                 f"vs exact reference)", fontsize=10)
    fig.tight_layout(rect=(0, 0.03 + 0.035 * ((len(methods) + 3) // 4), 1, 1))
    fig.savefig(out_png, dpi=120)
