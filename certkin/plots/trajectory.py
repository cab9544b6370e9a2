"""The margins of a trajectory along its path (needs the ``plot`` extra: matplotlib)."""
from __future__ import annotations

import numpy as np

from .figure import pyplot


def plot_margins(result, png):
    """The certified lower bound of every margin (det(A) aside) on each leaf of the search, against
    s = segment + t, clipped to [−50, 200]."""
    plt = pyplot()
    L = result.leaves
    s_lo, s_hi = L["segment"] + L["tlo"], L["segment"] + L["thi"]
    fig, ax = plt.subplots(figsize=(8, 4))
    for k, inst in enumerate(result.constraints.instances):
        if k == result.constraints.det_column:
            continue
        lo = np.clip(L["mlo"][:, k], -50, 200)
        ax.hlines(lo, s_lo, s_hi, lw=1, color=f"C{k % 10}")
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xlabel("s (segment index + t)")
    ax.set_ylabel("margin lower bound (clipped)")
    fig.tight_layout()
    fig.savefig(png, dpi=90)
    plt.close(fig)
