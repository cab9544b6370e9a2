"""The cell classification of a singularity run (matplotlib).

Cells are drawn with their certified status: singularity-free cells in
blue (det > 0) or green (det < 0), singular cells in red, undecided ones in
grey, each panel an image where a singular cell, however small, stays red.  A
3-D cell grid is shown as 2-D slices along its third varying coordinate (more
slices than panels: consecutive slices share a panel); a grid of more dimensions
is projected onto them, each drawn square showing the least favourable status of
the cells it stands for (singular, then undecided, then free), never a free
square over a singular cell.
"""
from __future__ import annotations

import numpy as np

from ..display import point
from .figure import plain, pyplot
from .raster import draw_boxes

COLOURS = {"free+": "#4c72b0", "free-": "#55a868", "singular": "#c44e52", "undecided": "#bbbbbb"}
WORST = ("free+", "free-", "undecided", "singular")       # the order in which a projection keeps the last


def _key(r):
    if r.status == "singularity-free":
        return "free+" if r.sign > 0 else "free-"
    return r.status


def _label(robot, name) -> str:
    return f"{name} ({'rad' if name in robot.angle_names else 'length unit of the robot file'})"


PIXELS = 200       # image pixels a panel side: fewer than the panel has on the page (about 330 at 110 dpi)
GRID = 30          # cells along each drawn axis up to which the cell borders are drawn (each then 6 pixels or more)


def plot_cells(robot, results, path, max_slices: int = 6):
    """Draw the cells of ``results`` (SingularityResult list) into ``path`` (PNG/SVG/PDF).

    Each panel is an image (``raster.draw_boxes``): every pixel a cell touches takes its status, the
    statuses drawn from the most favourable to the least (``WORST``), undecided and singular cells one
    pixel wider: a singular cell is red on the page however small, and never under a free colour.  The
    drawn axes are two along which the cells vary; an axis every cell spans whole (a fixed coordinate,
    or a single cell) is drawn as a band and named with its range."""
    plt = pyplot()
    from matplotlib.patches import Patch
    names = robot.pose_names
    lo = np.array([r.lo for r in results])
    hi = np.array([r.hi for r in results])
    varies = [i for i in range(len(names)) if len(np.unique(lo[:, i])) > 1]
    ax_x, ax_y = (varies + [i for i in range(len(names)) if i not in varies])[:2]
    rest = varies[2:]
    if rest:
        k = rest[0]
        slices = sorted(set(zip(lo[:, k], hi[:, k])))
        all_slabs = len(slices)     # more than max_slices: consecutive slices drawn together, none left out
        slabs = [(slices[g[0]][0], slices[g[-1]][1]) for g in np.array_split(np.arange(len(slices)), max_slices)
                 if len(g)] if len(slices) > max_slices else slices
    else:
        k, slabs, all_slabs = None, [None], 1
    drawn_lo, drawn_hi = lo[:, [ax_x, ax_y]].copy(), hi[:, [ax_x, ax_y]].copy()
    for c, i in enumerate((ax_x, ax_y)):
        if i not in varies:                     # a band: every cell spans it whole
            drawn_lo[:, c], drawn_hi[:, c] = 0.0, 1.0
    dlo, dhi = drawn_lo.min(axis=0), drawn_hi.max(axis=0)
    cols = min(3, len(slabs))
    rows = int(np.ceil(len(slabs) / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 4 * rows), squeeze=False)
    rank = np.array([WORST.index(_key(r)) for r in results])
    for a, slab in zip(axes.flat, slabs):
        mine = np.ones(len(results), bool) if slab is None else (lo[:, k] >= slab[0]) & (hi[:, k] <= slab[1])
        layers = [(drawn_lo[mine & (rank == w)], drawn_hi[mine & (rank == w)], COLOURS[name], int(w >= 2))
                  for w, name in enumerate(WORST)]
        draw_boxes(a, layers, dlo, dhi, PIXELS, square=False)
        for c, (i, lines) in enumerate(((ax_x, a.axvline), (ax_y, a.axhline))):
            edges = np.unique(np.concatenate([drawn_lo[mine, c], drawn_hi[mine, c]]))
            if i in varies and len(edges) <= GRID + 1:
                for e in edges:
                    lines(e, color="white", linewidth=0.3)
        a.set_xlim(dlo[0], dhi[0])
        a.set_ylim(dlo[1], dhi[1])
        for i, label, ticks in ((ax_x, a.set_xlabel, a.set_xticks), (ax_y, a.set_ylabel, a.set_yticks)):
            if i in varies:
                label(_label(robot, names[i]))
            else:
                label(f"{names[i]} in [{point(lo[0, i])}, {point(hi[0, i])}] (every cell)", fontsize=8)
                ticks([])
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
    if fixed := [i for i in range(len(names)) if i not in varies and i not in (ax_x, ax_y)]:
        notes.append("every cell: " + ", ".join(f"{names[i]} in [{point(lo[0, i])}, {point(hi[0, i])}]" for i in fixed))
    if len(slabs) < all_slabs:
        notes.append(f"{all_slabs} slices of {names[k]} in {len(slabs)} panels: each square its least favourable cell")
    fig.suptitle(f"{plain(robot.name)}: certified cell classification" + (f"\n({'; '.join(notes)})" if notes else ""),
                 fontsize=10)
    fig.tight_layout(rect=(0, 0.05, 1, 0.96))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def slab_title(name: str, slab) -> str:
    """The range of a slice of cells, exactly: rounded outward it would widen the singularity-free
    cells drawn under it beyond what was proved, rounded inward the singular ones."""
    return f"{name} in [{point(slab[0])}, {point(slab[1])}]"
