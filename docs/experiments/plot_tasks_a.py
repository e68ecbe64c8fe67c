"""Plots of the aggregation and synchronisation series in EXPERIMENTS.md, from the runs' summary.json files.

Usage: python3 docs/experiments/plot_tasks_a.py RUNS_DIR
where RUNS_DIR holds the run directories named in EXPERIMENTS.md (agg-s7, agg-s8, sync-ptsct, sync-sct).
Needs matplotlib. Writes PNGs next to this script.
"""

import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = Path(__file__).parent


def series(run_dir: Path) -> list:
    return json.loads((run_dir / "summary.json").read_text())["metrics"]["series"]


def aggregation(runs: Path) -> None:
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.6))
    for name in sorted(p.name for p in runs.glob("agg-s*") if p.is_dir()):
        s = series(runs / name)
        t = [x["time_s"] for x in s]
        ax1.plot(t, [x["clusters"] for x in s], label=f"seed {name[5:]}")
        ax2.plot(t, [x["largest"] / 300 for x in s], label=f"seed {name[5:]}")
    ax1.set(xlabel="time (s)", ylabel="clusters", title="Aggregation: number of clusters")
    ax2.set(xlabel="time (s)", ylabel="fraction of robots", title="Largest cluster", ylim=(0, 1))
    ax2.axhline(0.9, color="grey", linestyle=":", linewidth=1)
    ax1.legend()
    fig.tight_layout()
    fig.savefig(HERE / "aggregation_clusters.png", dpi=110)


def synchronisation(runs: Path) -> None:
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.6))
    for name, label in [("sync-ptsct", "ptSCT"), ("sync-sct", "plain SCT")]:
        s = series(runs / name)
        t = [x["time_s"] for x in s]
        ax1.plot(t, [x["phase"]["order_parameter"] if x["phase"] else None for x in s], label=label)
        ax2.plot(t, [x["window_fraction"] for x in s], label=label)
    ax1.set(xlabel="time (s)", ylabel="R", title="Order parameter of the phases", ylim=(0, 1))
    ax1.axhline(0.9, color="grey", linestyle=":", linewidth=1)
    ax2.set(xlabel="time (s)", ylabel="fraction", title="Largest fraction flashing within 5 ticks", ylim=(0, 1))
    ax1.legend()
    fig.tight_layout()
    fig.savefig(HERE / "synchronisation_order.png", dpi=110)


if __name__ == "__main__":
    runs_dir = Path(sys.argv[1])
    aggregation(runs_dir)
    synchronisation(runs_dir)
