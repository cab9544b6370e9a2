"""The robot drawn at some poses: base joints, platform and legs (matplotlib).

A planar robot is drawn in its plane, a spatial one in 3-D; one panel per pose (at most
``MAX_POSES``).  The platform points come from the robot's own model at the pose (the midpoints of
their enclosures: a drawing, not a claim).  Lengths are in the unit of the robot file.
"""
from __future__ import annotations

import textwrap

import numpy as np

from .figure import plain, pyplot

MAX_POSES = 8
UNIT = "length unit of the robot file"


def platform_points(robot, pose) -> np.ndarray:
    """World coordinates of the platform joints B_i at a pose (floats or exact texts), (n, dim)."""
    p = robot.platform_points(robot.pose_box(pose))
    return 0.5 * (np.asarray(p.lo, dtype=float) + np.asarray(p.hi, dtype=float))


def base_points(robot) -> np.ndarray:
    return np.array([[float(c) for c in a] for a in robot.base])


def plot_robot(robot, poses, path, title: str = ""):
    """Draw ``robot`` at each ``(label, pose)`` of ``poses`` into ``path`` (PNG)."""
    plt = pyplot()
    shown = list(poses)[:MAX_POSES]
    spatial = robot.dim == 3
    cols = min(4, max(1, len(shown)))
    rows = int(np.ceil(max(1, len(shown)) / cols))
    width = max(5.0, 3.4 * cols)
    fig = plt.figure(figsize=(width, 3.3 * rows + 0.5 if cols > 1 else 4.6))
    A = base_points(robot)
    for k, (label, pose) in enumerate(shown or [("geometry only", None)]):
        ax = fig.add_subplot(rows, cols, k + 1, **({"projection": "3d"} if spatial else {}))
        B = platform_points(robot, pose) if pose is not None else None
        _draw(ax, A, B)
        ax.set_title(plain(label), fontsize=8)
        ax.set_xlabel(f"x ({UNIT})", fontsize=6)
        ax.set_ylabel(f"y ({UNIT})", fontsize=6)
        if spatial:
            ax.set_zlabel("z", fontsize=6)
        else:
            ax.set_aspect("equal", adjustable="datalim")
        ax.tick_params(labelsize=6)
    handles, labels = fig.axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=7)
    more = f" (first {MAX_POSES} of {len(poses)} poses)" if len(poses) > MAX_POSES else ""
    fig.suptitle(textwrap.fill(plain((title or robot.name) + more), int(width * 13)), fontsize=9)   # never clipped
    fig.tight_layout(rect=(0, 0.06, 1, 0.95))
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _draw(ax, A, B):
    """Base joints (black squares, base polygon), legs (grey) and platform (blue polygon)."""
    def line(P, **kw):
        ax.plot(*[P[:, j] for j in range(P.shape[1])], **kw)
    closed = np.vstack([A, A[:1]])
    line(closed, color="black", lw=1.2, label="base")
    ax.scatter(*[A[:, j] for j in range(A.shape[1])], color="black", marker="s", s=12)
    if B is None:
        return
    for k, (a, b) in enumerate(zip(A, B)):
        line(np.vstack([a, b]), color="grey", lw=1, label="legs" if k == 0 else None)
    line(np.vstack([B, B[:1]]), color="#1f5fbf", lw=1.6, label="platform")
    ax.scatter(*[B[:, j] for j in range(B.shape[1])], color="#1f5fbf", s=10)
