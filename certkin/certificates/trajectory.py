"""Trajectory certificates: per path, its exact poses, the constraint instances and the leaves of
the search with one state character per instance (``proofs.trajectory`` re-checks them)."""
from __future__ import annotations

from .writing import pose_certificate

_STATE_CHARS = {1: "+", -1: "-", 0: "?"}


def trajectory_claim(result) -> dict:
    """One path: its exact poses, the constraint instances, the leaves with one state character
    per instance ('+' proved satisfied, '-' proved violated, '?' not decided; for the singularity
    instance '+'/'-' is the proved sign of det(A)), the verdict and the violations."""
    c = result.constraints
    L = result.leaves
    dcol = c.det_column
    states = []
    for row, lo, hi in zip(L["state"], L["mlo"], L["mhi"]):
        chars = [_STATE_CHARS[int(v)] for v in row]
        if dcol is not None:
            chars[dcol] = "+" if lo[dcol] > 0 else "-" if hi[dcol] < 0 else "?"
        states.append("".join(chars))
    return {"path": [list(t) for t in result.path.texts],
            "instances": [i.to_json() for i in c.instances],
            "status": result.status,
            "violations": result.violations,
            "leaves": {"segment": [int(s) for s in L["segment"]],
                       "t": [[float(a), float(b)] for a, b in zip(L["tlo"], L["thi"])],
                       "state": states}}


def trajectory_certificate(results) -> dict:
    """Certificate for one TrajectoryResult or a list of them (one claim per path)."""
    return pose_certificate("trajectory", results, trajectory_claim)
