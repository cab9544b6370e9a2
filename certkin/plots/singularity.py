"""The cell classification of a singularity run (needs the ``plot`` extra: matplotlib).

Cells are drawn with their certified status: singularity-free cells in
blue (det > 0) or green (det < 0), singular cells in red, undecided ones in
grey.  A 3-D cell grid is shown as 2-D slices along its last variable (more
slices than panels: consecutive slices share a panel); a grid of more dimensions
is projected onto them, each drawn square showing the least favourable status of
the cells it stands for (singular, then undecided, then free), never a free
square over a singular cell.
"""
from __future__ import annotations

import numpy as np

from ..display import point
from .figure import pyplot

COLOURS = {"free+": "#4c72b0", "free-": "#55a868", "singular": "#c44e52", "undecided": "#bbbbbb"}
WORST = ("free+", "free-", "undecided", "singular")       # the order in which a projection keeps the last


def _key(r):
    if r.status == "singularity-free":
        return "free+" if r.sign > 0 else "free-"
    return r.status


def _label(robot, name) -> str:
    return f"{name} ({'rad' if name in robot.angle_names else 'length unit of the robot file'})"


def plot_cells(robot, results, path, max_slices: int = 6):
    """Draw the cells of ``results`` (SingularityResult list) into ``path`` (PNG/SVG/PDF)."""
    plt = pyplot()
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Patch
    names = robot.pose_names
    lo = np.array([r.lo for r in results])
    hi = np.array([r.hi for r in results])
    free = [i for i in range(len(names)) if np.any(hi[:, i] > lo[:, i])]
    if len(free) < 2:
        free = list(range(min(2, len(names))))
    ax_x, ax_y = free[0], free[1]
    rest = free[2:]
    if rest:
        k = rest[0]
        slices = sorted(set(zip(lo[:, k], hi[:, k])))
        all_slabs = len(slices)     # more than max_slices: consecutive slices drawn together, none left out
        slabs = [(slices[g[0]][0], slices[g[-1]][1]) for g in np.array_split(np.arange(len(slices)), max_slices)
                 if len(g)] if len(slices) > max_slices else slices
    else:
        k, slabs, all_slabs = None, [None], 1
    cols = min(3, len(slabs))
    rows = int(np.ceil(len(slabs) / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 4 * rows), squeeze=False)
    rank = np.array([WORST.index(_key(r)) for r in results])
    for a, slab in zip(axes.flat, slabs):
        mine = np.ones(len(results), bool) if slab is None else (lo[:, k] >= slab[0]) & (hi[:, k] <= slab[1])
        square = np.stack([lo[mine, ax_x], lo[mine, ax_y], hi[mine, ax_x], hi[mine, ax_y]], 1)
        squares, which = np.unique(square, axis=0, return_inverse=True)     # the cells drawn on one square
        worst = np.zeros(len(squares), np.int64)
        np.maximum.at(worst, which.ravel(), rank[mine])
        corners = squares[:, [[0, 1], [2, 1], [2, 3], [0, 3]]]         # (squares, 4 corners, x y)
        a.add_collection(PolyCollection(corners, closed=True, facecolor=[COLOURS[WORST[w]] for w in worst],
                                        edgecolor="white", linewidth=0.3))   # (one collection of arrays: a patch
        # per square took seconds for 125 000 cells)
        a.set_xlim(lo[:, ax_x].min(), hi[:, ax_x].max())
        a.set_ylim(lo[:, ax_y].min(), hi[:, ax_y].max())
        a.set_xlabel(_label(robot, names[ax_x]))
        a.set_ylabel(_label(robot, names[ax_y]))
        if slab is not None:
            a.set_title(slab_title(names[k], slab), fontsize=9)
    for a in list(axes.flat)[len(slabs):]:
        a.axis("off")
    legend = [Patch(color=COLOURS[c], label=t) for c, t in
              [("free+", "free, det > 0"), ("free-", "free, det < 0"), ("singular", "singular"), ("undecided", "undecided")]]
    fig.legend(handles=legend, loc="lower center", ncol=4, fontsize=8)
    notes = []
    if len(rest) > 1:
        notes.append(f"projected over {', '.join(names[i] for i in rest[1:])}: each square shows its least "
                     "favourable cell")
    if len(slabs) < all_slabs:
        notes.append(f"{all_slabs} slices of {names[k]} in {len(slabs)} panels: each square its least favourable cell")
    fig.suptitle(f"{robot.name}: certified cell classification" + (f"\n({'; '.join(notes)})" if notes else ""),
                 fontsize=10)
    fig.tight_layout(rect=(0, 0.05, 1, 0.96))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def slab_title(name: str, slab) -> str:
    """The range of a slice of cells, exactly: rounded outward it would widen the singularity-free
    cells drawn under it beyond what was proved, rounded inward the singular ones."""
    return f"{name} in [{point(slab[0])}, {point(slab[1])}]"
