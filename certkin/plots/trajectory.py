"""The margins of a trajectory along its path, one panel per constraint family (matplotlib).

Each curve is the certified lower bound of one margin on each leaf of the search, against
s = segment + t; a range holding every failing instant of a constraint proved to fail is shaded
red (the range is an enclosure: not every instant in it need fail), one where it may fail orange,
the undecided ones grey.  The singularity panel shows the lower bound of |det(A)|
on a logarithmic axis (nothing clipped).
"""
from __future__ import annotations

import numpy as np

from .figure import plain, pyplot

UNITS = {"leg-length": "margin (length unit)", "interference": "clearance margin (length unit)",
         "joints": "margin (cosine / direction)", "singularity": "|det(A)| lower bound"}
SHADES = (("proved to fail: its failing instants lie within", "#d62728", 0.25),
          ("may fail: its failing instants lie within", "#ff7f0e", 0.18), ("undecided", "#999999", 0.2))


def families(result) -> list[str]:
    """The constraint families of a result, in the order of its instances."""
    out = []
    for inst in result.constraints.instances:
        if inst.constraint not in out:
            out.append(inst.constraint)
    return out


def plot_margins(result, png):
    """One panel per constraint family of ``result`` (a ``TrajectoryResult``) into ``png``."""
    plt = pyplot()
    names = families(result)
    L = result.leaves
    s_lo, s_hi = L["segment"] + L["tlo"], L["segment"] + L["thi"]
    order = np.argsort(s_lo, kind="stable")
    fig, axes = plt.subplots(len(names), 1, figsize=(8, 2.3 * len(names) + 0.6), sharex=True, squeeze=False)
    for ax, family in zip(axes[:, 0], names):
        for k, inst in enumerate(result.constraints.instances):
            if inst.constraint != family:
                continue
            if k == result.constraints.det_column:
                lo, hi = L["mlo"][:, k], L["mhi"][:, k]
                y = np.where(lo > 0, lo, np.where(hi < 0, -hi, np.nan))
                ax.set_yscale("log")
            else:
                y = L["mlo"][:, k]
            label = family if not inst.legs else f"{'-'.join(map(str, inst.legs))} {inst.detail or ''}".strip()
            ax.step(np.r_[s_lo[order], s_hi[order][-1:]], np.r_[y[order], y[order][-1:]], where="post", lw=1,
                    label=plain(label))
        if family != "singularity":
            ax.axhline(0, color="black", lw=0.8)
        _shade(ax, result, family)
        ax.set_ylabel(UNITS.get(family, "margin"), fontsize=7)
        ax.set_title(family, fontsize=8, loc="left")
        ax.tick_params(labelsize=7)
        handles, labels = ax.get_legend_handles_labels()
        ax.legend(handles, labels, fontsize=6, ncol=min(5, max(1, len(labels) // 3 + 1)), loc="upper right",
                  title="legs", title_fontsize=6)
    axes[-1, 0].set_xlabel("s = segment index + t (t in [0, 1] along each segment)", fontsize=8)
    fig.suptitle(f"{plain(result.robot.name)}: certified margins along the path ({result.status})", fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    fig.savefig(png, dpi=90)
    plt.close(fig)


def _shade(ax, result, family):
    """Shade the forbidden, possibly forbidden and undecided s-ranges of a family: for each kind, the
    union of its ranges, joined across gaps narrower than a pixel (a search down to the floats'
    resolution leaves thousands of ranges, once one span each: 13 s to draw 6000)."""
    from matplotlib.patches import Patch
    L = result.leaves
    gap = float(np.max(L["segment"] + L["thi"]) - np.min(L["segment"] + L["tlo"])) / 4000 if len(L["tlo"]) else 0.0
    kinds = [[v["s"] for v in result.violations if v["constraint"] == family and v["certain"] == sure]
             for sure in (True, False)] + [[u["s"] for u in result.undecided]]
    used = set()
    for (label, colour, alpha), ranges in zip(SHADES, kinds):
        for a, b in _union(ranges, gap):
            ax.axvspan(a, b, color=colour, alpha=alpha, lw=0)
            used.add(label)
    if used:
        patches = [Patch(color=c, alpha=a, label=n) for n, c, a in SHADES if n in used]
        ax.add_artist(ax.legend(handles=patches, fontsize=6, loc="lower left"))


def _union(ranges, gap: float) -> list:
    """The ranges ``[a, b]`` joined where they overlap or lie less than ``gap`` apart (sorted)."""
    out = []
    for a, b in sorted(ranges):
        if out and a <= out[-1][1] + gap:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    return out
