"""Pictures of workspace results: the paving of a section with its exact arcs, and the section
areas of a volume per slab (needs the ``plot`` extra: matplotlib)."""
from __future__ import annotations

import math

import numpy as np

from ..display import lower, outward, upper
from ..engine import EXCLUDED, PROVED, UNDECIDED
from .figure import plain, pyplot
from .raster import draw_boxes

COLOURS = {"inside": "#55a868", "boundary": "#f2c14e", "outside": "#e6e6e6", "arc": "#1f3b73"}


def _rects(ax, lo, hi, colour, edge):
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Rectangle
    if not len(lo):
        return
    patches = [Rectangle((a[0], a[1]), b[0] - a[0], b[1] - a[1]) for a, b in zip(lo, hi)]
    ax.add_collection(PatchCollection(patches, facecolor=colour, edgecolor=edge, linewidth=0.2))


MAX_PATCHES = 20_000     # boxes drawn one by one; a larger paving is drawn as an image (boxes far below a pixel)
PIXELS = 400            # fewer than the axes have on the page (about 600 at 120 dpi): every pixel is seen


def _raster(ax, paving, dlo, dhi):
    """The paving as an image of at most ``PIXELS`` a side, square pixels (``raster.draw_boxes``):
    outside first, then inside, then boundary on top, a boundary box one pixel wider on every side: a
    page pixel is green only where no boundary box touches it."""
    layers = [(*paving.boxes(kind), COLOURS[name], grow)
              for kind, name, grow in ((EXCLUDED, "outside", 0), (PROVED, "inside", 0), (UNDECIDED, "boundary", 1))]
    draw_boxes(ax, layers, dlo, dhi, PIXELS)


def plot_section(result, path):
    """The paving (inside green, boundary yellow, outside grey) and the exact arcs (dark blue)."""
    plt = pyplot()
    from matplotlib.patches import Patch
    fig, ax = plt.subplots(figsize=(6.4, 6.0))
    if result.paving is not None:
        dlo, dhi = result.domain
        blo, bhi = result.paving.boxes(UNDECIDED)
        pixel = float(np.max(np.asarray(dhi, float) - np.asarray(dlo, float))) / PIXELS
        if sum(result.paving.counts().values()) > MAX_PATCHES or np.any(np.min(bhi - blo, axis=1) < pixel):
            _raster(ax, result.paving, dlo, dhi)        # (a boundary box below a pixel: drawn at least a pixel wide)
        else:                                           # boundary boxes on top, never hidden by an inside box
            for kind, name in ((EXCLUDED, "outside"), (PROVED, "inside"), (UNDECIDED, "boundary")):
                lo, hi = result.paving.boxes(kind)
                _rects(ax, lo, hi, COLOURS[name], "white" if name != "outside" else "#f7f7f7")
        ax.set_xlim(dlo[0], dhi[0])
        ax.set_ylim(dlo[1], dhi[1])
    for arc in result.boundary.arcs if result.boundary.decided else []:
        cx, cy = arc["center"]
        r = 0.5 * (arc["radius"][0] + arc["radius"][1])
        a0 = math.atan2(arc["from"][1] - cy, arc["from"][0] - cx)
        sweep = 0.5 * (arc["sweep"][0] + arc["sweep"][1])
        t = a0 + np.linspace(0.0, sweep, 400)
        ax.plot(cx + r * np.cos(t), cy + r * np.sin(t), color=COLOURS["arc"], linewidth=1.2)
    ax.set_aspect("equal")
    ax.set_xlabel("x (length unit of the robot file)")
    ax.set_ylabel("y (length unit of the robot file)")
    names = [n for n in result.robot.pose_names if n in result.robot.angle_names]
    orient = ", ".join(f"{n}={v}" for n, v in zip(names, result.orientation))
    zpart = "" if result.z is None else f"z = {result.z}, "
    area = result.boundary.area
    exact = f"exact area {outward(float(area.lo), float(area.hi))}" if area is not None else "exact area undecided"
    ax.set_title(f"{plain(result.robot.name)}\n{zpart}{orient}: {exact}\npaving: area between "
                 f"{lower(result.inner, 6)} and {upper(result.outer, 6)}", fontsize=9)
    legend = [Patch(color=COLOURS["inside"], label="inside"), Patch(color=COLOURS["boundary"], label="boundary"),
              Patch(color=COLOURS["outside"], label="outside"), Patch(color=COLOURS["arc"], label="exact arcs")]
    ax.legend(handles=legend, loc="upper right", fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_volume(result, path):
    """Inner and outer section areas per slab, against z."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    ar = np.array(result.areas()).reshape(-1, 2)
    z = result.bounds
    ax.stairs(ar[:, 1], z, color="#f2c14e", fill=True, label="outer (inside + boundary)")
    ax.stairs(ar[:, 0], z, color="#55a868", fill=True, label="inner (inside)")
    vin, vout = result.volume()
    ax.set_xlabel("z (length unit of the robot file)")
    ax.set_ylabel("section area (length unit squared)")
    ax.set_title(f"{plain(result.robot.name)}: volume between {lower(vin, 6)} and {upper(vout, 6)}", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
