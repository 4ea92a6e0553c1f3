"""Compression plot: per dataset, the lossless octree and zstd -3 of the raw array, as % of the raw
bytes (lower is smaller), with the round-trip verdict under each dataset name."""
import matplotlib.pyplot as plt


def plot(data, out_png):
    rows = data["datasets"]
    names = [r["name"].replace(".nii.gz", "") + ("" if r["round_trip_exact"] else "\n(MISMATCH)") for r in rows]
    octree = [r["percent_of_raw"] for r in rows]
    zstd = [r["zstd3_percent_of_raw"] for r in rows]
    x = range(len(rows))
    width = 0.4
    fig, ax = plt.subplots(figsize=(max(6.0, 0.75 * len(rows) + 2), 4.5))
    bars_o = ax.bar([i - width / 2 for i in x], octree, width, label="octree (.oct file)")
    bars_z = ax.bar([i + width / 2 for i in x], zstd, width, label="zstd -3 of raw")
    for bars in (bars_o, bars_z):
        for b in bars:
            ax.annotate(f"{b.get_height():.1f}", (b.get_x() + b.get_width() / 2, b.get_height()),
                        ha="center", va="bottom", fontsize=7)
    ax.set_xticks(list(x))
    ax.set_xticklabels(names, rotation=40, ha="right", fontsize=8)
    ax.set_ylabel("% of raw bytes")
    ax.set_title(f"Lossless size per dataset (synthetic at {data['size']}^3, {data['threads']} threads)")
    ax.legend()
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out_png, dpi=120)
