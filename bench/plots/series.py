"""Series plot: frames/s per step at each resolution (Table 4 analogue), bytes per step of the octree
against zstd -3 of the raw step (Table 1 analogue), and resident memory of the mapped file as steps
are rendered, beside the bytes of the steps rendered."""
import matplotlib.pyplot as plt

MIB = 1024.0 * 1024.0


def plot(data, out_png):
    steps = [s["step"] for s in data["per_step"]]
    panels = 3 if data["rss"]["points"] else 2
    fig, axes = plt.subplots(1, panels, figsize=(5.2 * panels, 4.2))

    ax = axes[0]
    for i, res in enumerate(data["resolutions"]):
        ax.plot(steps, [1.0 / s["seconds"][i] for s in data["per_step"]], marker=".", label=f"{res}^2")
    ax.set_xlabel("time step")
    ax.set_ylabel("frames / s")
    ax.set_title(f"plume-series {data['size']}^3, {data['threads']} threads")
    ax.set_ylim(bottom=0)
    ax.legend()
    ax.grid(alpha=0.3)

    ax = axes[1]
    ax.plot(steps, [s["octree_bytes"] / MIB for s in data["per_step"]], marker=".", label="octree")
    ax.plot(steps, [s["zstd3_bytes"] / MIB for s in data["per_step"]], marker=".", label="zstd -3 of raw")
    ax.axhline(data["per_step"][0]["raw_bytes"] / MIB, color="gray", ls="--", label="raw")
    ax.set_xlabel("time step")
    ax.set_ylabel("MiB per step")
    ax.set_yscale("log")
    ax.set_title("bytes per step")
    ax.legend()
    ax.grid(alpha=0.3)

    if panels == 3:
        ax = axes[2]
        pts = data["rss"]["points"]
        n = [p["rendered"] for p in pts]
        ax.plot(n, [p["mapped_resident_bytes"] / MIB for p in pts], marker="o", label="resident part of the mapping")
        ax.plot(n, [p["rendered_step_bytes"] / MIB for p in pts], ls="--", label="bytes of the steps rendered")
        ax.axhline(data["rss"]["file_bytes"] / MIB, color="gray", ls=":", label="whole file")
        ax.set_xlabel("steps rendered")
        ax.set_ylabel("MiB")
        ax.set_title(f"{data['rss']['steps_in_file']}-step {data['rss']['size']}^3 series, mmap'd")
        ax.legend()
        ax.grid(alpha=0.3)

    fig.tight_layout()
    fig.savefig(out_png, dpi=120)
