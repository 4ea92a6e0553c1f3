"""Frame time per method for `octiso-bench packets`: one group of bars per case (dataset, isovalue,
image, threads), one bar per method, log scale, so the gap to the mesh reads as a ratio."""
import matplotlib.pyplot as plt
import numpy as np


def plot(data, out_png):
    cases = data["cases"]
    if not cases:
        return
    methods = list(cases[0]["min_seconds"].keys())
    labels = [f'{c["dataset"]} @{c["iso"]:g}\n{c["image"]}^2, {c["threads"]}t' for c in cases]
    x = np.arange(len(cases))
    width = 0.8 / len(methods)
    fig, ax = plt.subplots(figsize=(max(8, 1.3 * len(cases)), 5))
    for i, m in enumerate(methods):
        ms = [1e3 * c["min_seconds"].get(m, float("nan")) for c in cases]
        ax.bar(x + (i - (len(methods) - 1) / 2) * width, ms, width, label=m)
    ax.set_xticks(x)
    ax.set_xticklabels(labels, fontsize=7)
    ax.set_yscale("log")
    ax.set_ylabel("frame time, ms (min of repeats)")
    ax.set_title("packet traversal vs single rays vs the extracted mesh (Embree)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out_png, dpi=110)
