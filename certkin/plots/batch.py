"""Pictures of a batch campaign (matplotlib): the jobs by verdict, and how long they took."""
from __future__ import annotations

import numpy as np

from ..display import counted
from .figure import pyplot


def _null_formatter():
    from matplotlib.ticker import NullFormatter
    return NullFormatter()


def _whole_numbers():
    from matplotlib.ticker import MaxNLocator
    return MaxNLocator(integer=True)


COLOURS = {"complete": "#55a868", "singularity-free": "#55a868", "feasible": "#55a868", "found": "#55a868",
           "non-empty": "#55a868", "tracked": "#55a868", "singular": "#c44e52", "infeasible": "#c44e52",
           "empty": "#8172b2", "undecided": "#bbbbbb", "incomplete": "#bbbbbb", "error": "#dd8452",
           "failed": "#000000", "pending": "#eeeeee", "complete-with-clusters": "#ccb974"}


def plot_campaign(summary: dict, path):
    """Two panels: the number of jobs per command and verdict, and the histogram of job times."""
    plt = pyplot()
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.6))
    keys = list(summary["counts"])
    counts = [summary["counts"][k] for k in keys]
    colours = [COLOURS.get(k.split(" ", 1)[-1], "#4c72b0") for k in keys]
    bars = a.barh(range(len(keys)), counts, color=colours, edgecolor="black", linewidth=0.4)
    for bar, key in zip(bars, keys):
        bar.set_label(key)
    a.set_yticks(range(len(keys)), keys, fontsize=7)
    a.invert_yaxis()
    a.xaxis.set_major_locator(_whole_numbers())         # (counts of jobs: no 0.5 ticks)
    a.set_xlabel("jobs", fontsize=8)
    a.set_title("jobs by command and verdict", fontsize=9)
    a.legend(fontsize=6, loc="lower right")
    times = np.array([r["seconds"] for r in summary["results"] if r["verdict"] != "pending"])
    if len(times):
        times = np.maximum(times, 1e-4)
        bins = np.logspace(np.log10(times.min()), np.log10(times.max() * 1.01 + 1e-4), 30)
        b.hist(times, bins=bins, color="#4c72b0", label=counted(len(times), "job"))
    else:                                               # (an interrupted batch before any job ended)
        b.text(0.5, 0.5, "no job ended", ha="center", va="center", transform=b.transAxes, fontsize=8)
    b.set_xscale("log")
    b.xaxis.set_minor_formatter(_null_formatter())
    b.set_xlabel("time per job (s, wall clock in its worker)", fontsize=8)
    b.yaxis.set_major_locator(_whole_numbers())
    b.set_ylabel("jobs", fontsize=8)
    b.set_title("job times", fontsize=9)
    if len(times):
        b.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
