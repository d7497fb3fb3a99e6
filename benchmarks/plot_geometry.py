"""Plot the geometry micro-benchmarks (Google Benchmark JSON) into a PNG beside it."""

import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(path):
    data = json.loads(Path(path).read_text())["benchmarks"]
    fig, ax = plt.subplots(figsize=(7, 4))
    names = [b["name"] for b in data]
    times = [b["real_time"] for b in data]
    ax.barh(names, times)
    ax.set_xscale("log")
    ax.set_xlabel(f"wall time per call ({data[0]['time_unit']})")
    for b in data:
        if "items_per_second" in b:
            print(f"{b['name']}: {b['items_per_second'] / 1e6:.2f} M closest points/s")
        else:
            print(f"{b['name']}: {b['real_time']:.1f} {b['time_unit']}")
    fig.tight_layout()
    out = Path(path).with_suffix(".png")
    fig.savefig(out, dpi=110)
    print(f"figures in {Path(path).resolve()} and {out.resolve()}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "benchmarks/results/geometry.json")
