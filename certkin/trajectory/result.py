"""The verdict on one path, with the leaves of the search that prove it: ``feasible``,
``infeasible`` or ``undecided``, certified minimum margins, and the t-ranges where a constraint may
fail (see ``trajectory.verify``)."""
from __future__ import annotations

from dataclasses import dataclass, field
import math

import numpy as np

from ..certificates import trajectory_certificate
from ..display import counted
from .constraints import Constraints
from .families.base import SATISFIED, UNKNOWN, VIOLATED
from .path import Path


@dataclass(repr=False)
class TrajectoryResult:
    """The verdict on one path, with the leaves that prove it."""

    robot: object
    path: Path
    constraints: Constraints
    status: str = "undecided"
    leaves: dict = field(default_factory=dict)    # segment, tlo, thi (arrays), state (L, K), mlo, mhi
    margins: list = field(default_factory=list)
    violations: list = field(default_factory=list)
    undecided: list = field(default_factory=list)
    det_sign: int = 0
    stats: dict = field(default_factory=dict)
    indices: list | None = None

    def __repr__(self):
        return (f"<TrajectoryResult {self.status}: {counted(self.path.segments, 'segment')}, "
                f"{counted(len(self.margins), 'margin')}, {counted(len(self.violations), 'violation')}, "
                f"{counted(len(self.undecided), 'undecided range')}>")

    def to_json(self) -> dict:
        """The result as a JSON-ready dict (``json.dumps(result.to_json())``): the document of
        ``certkin trajectory --json``."""
        c = self.constraints
        out = {"problem": "trajectory", "status": self.status,
               "path": [dict(zip(self.robot.pose_names, t)) for t in self.path.texts],
               "constraints": sorted({i.constraint for i in c.instances}),
               "skipped": dict(c.skipped),
               "not_asked": list(c.not_asked),
               "partly_checked": dict(c.partial),
               "margins": self.margins,
               "violations": self.violations,
               "undecided": self.undecided,
               "stats": self.stats}
        if c.det is not None:
            out["det_sign"] = self.det_sign
        if self.indices is not None:
            out["indices"] = self.indices
        return out

    def certificate(self):
        """The certificate (``certificates.Document``: ``.write(path)``, or ``proofs.check`` it in memory)."""
        return trajectory_certificate([self])


def _runs(mask_sorted, s_lo, s_hi):
    """Maximal runs of consecutive True leaves -> list of (first, last) indices."""
    idx = np.nonzero(mask_sorted)[0]
    if not len(idx):
        return []
    breaks = np.nonzero((np.diff(idx) > 1) | (s_lo[idx[1:]] > s_hi[idx[:-1]]))[0]
    starts = np.concatenate([[idx[0]], idx[breaks + 1]])
    ends = np.concatenate([idx[breaks], [idx[-1]]])
    return list(zip(starts.tolist(), ends.tolist()))


def _interval(lo, hi):
    """[lo, hi] for JSON; an infinite bound (not computed) is null."""
    return [float(lo) if np.isfinite(lo) else None, float(hi) if np.isfinite(hi) else None]


def conclude(r: TrajectoryResult, best=None) -> None:
    """The verdict, margins and violations of a path from its leaves; ``best``: upper bounds of
    the minimum margins found during the search (intervals or instants evaluated), per column."""
    c = r.constraints
    L = r.leaves
    s_lo = L["segment"] + L["tlo"]
    s_hi = L["segment"] + L["thi"]
    state = L["state"]
    dcol = c.det_column
    certain = False
    lo_min, hi_min = L["mlo"].min(axis=0), L["mhi"].min(axis=0)
    if best is not None:
        hi_min = np.minimum(hi_min, best)
    open_cols = (state != SATISFIED).any(axis=0)
    for k, inst in enumerate(c.instances):
        if k == dcol:
            continue
        entry = inst.to_json()
        # proved to hold at every instant: the minimum margin is >= 0, whatever the enclosure gave
        entry["margin"] = _interval(lo_min[k] if open_cols[k] else max(lo_min[k], 0.0), hi_min[k])
        r.margins.append(entry)
        if not open_cols[k]:
            continue
        proved = np.concatenate([[0], np.cumsum(state[:, k] == VIOLATED)])    # (a run's: one subtraction)
        for a, b in _runs(state[:, k] != SATISFIED, s_lo, s_hi):
            sure = bool(proved[b + 1] > proved[a])
            certain |= sure
            r.violations.append({**inst.to_json(), **_where(L, a, b), "certain": sure})
    if dcol is not None:
        sign = np.where(L["mlo"][:, dcol] > 0, 1, np.where(L["mhi"][:, dcol] < 0, -1, 0))
        mig = np.where(sign > 0, L["mlo"][:, dcol], np.where(sign < 0, -L["mhi"][:, dcol], 0.0))
        mag = np.maximum(np.abs(L["mlo"][:, dcol]), np.abs(L["mhi"][:, dcol]))
        signs = set(sign[sign != 0].tolist())
        entry = c.instances[dcol].to_json()
        entry["margin"] = _interval(mig.min(), mag.min())      # min over the path of |det A|
        entry["sign"] = signs.pop() if len(signs) == 1 and (sign != 0).all() else 0
        r.det_sign = entry["sign"]
        r.margins.append(entry)
        crossing = len(set(sign[sign != 0].tolist())) > 1
        certain |= crossing
        for a, b in _runs(sign == 0, s_lo, s_hi):
            before = sign[a - 1] if a > 0 else 0
            after = sign[b + 1] if b + 1 < len(sign) else 0
            sure = bool(before and after and before != after)
            r.violations.append({**c.instances[dcol].to_json(), **_where(L, a, b), "certain": sure})
    unknown = (state == UNKNOWN).any(axis=1)
    if certain:
        r.status = "infeasible"
    elif not unknown.any() and not r.violations:
        r.status = "feasible"
    else:
        r.status = "undecided"
    for a, b in _runs(unknown, s_lo, s_hi):
        r.undecided.append(_where(L, a, b))


def _where(L, a, b) -> dict:
    """The t-range of leaves a..b: local t when in one segment, and the global s."""
    # k + t may round: widen outward by one ulp if so.  With k a whole number and 0 <= t <= 1 <= k
    # (or k = 0), s - k is exact (Fast2Sum: Dekker 1971), so comparing it with t compares s with k + t
    # exactly, as Fractions did at 80 us a range (a fine search has thousands, built after its budget).
    k0, k1 = float(L["segment"][a]), float(L["segment"][b])
    s0 = k0 + float(L["tlo"][a])
    s1 = k1 + float(L["thi"][b])
    if s0 - k0 > float(L["tlo"][a]):
        s0 = math.nextafter(s0, -math.inf)
    if s1 - k1 < float(L["thi"][b]):
        s1 = math.nextafter(s1, math.inf)
    out = {"s": [s0, s1]}
    if L["segment"][a] == L["segment"][b]:
        out["segment"] = int(L["segment"][a])
        out["t"] = [float(L["tlo"][a]), float(L["thi"][b])]
    return out
