"""Trajectory certificates (``docs/certificates.md``): per path, its exact poses, the constraint
instances, the verdict and violations (header), and the leaves of the search as body arrays: segment,
t-interval and one state per instance (0 nothing claimed, 1 satisfied — det(A) > 0 for the
singularity instance —, 2 violated — det(A) < 0) (``proofs.trajectory`` re-checks them)."""
from __future__ import annotations

import numpy as np

from .writing import Array, Document, header


def _states(result):
    L, dcol = result.leaves, result.constraints.det_column
    s = np.asarray(L["state"], np.int64)
    out = np.where(s == 1, 1, np.where(s == -1, 2, 0)).astype(np.uint8).reshape(len(s), -1)
    if dcol is not None:
        lo, hi = np.asarray(L["mlo"])[:, dcol], np.asarray(L["mhi"])[:, dcol]
        out[:, dcol] = np.where(lo > 0, 1, np.where(hi < 0, 2, 0))
    return out


def trajectory_certificate(results, route=None) -> Document:
    """The certificate of one TrajectoryResult or a list of them (one claim per path); ``route``: (start,
    goal) pose texts of a plan whose paths join them end to end (``proofs`` checks that they do)."""
    results = results if isinstance(results, (list, tuple)) else [results]
    robot, claims, first = results[0].robot, [], 0
    for r in results:
        count = len(r.leaves["segment"])
        claims.append({"path": [list(t) for t in r.path.texts], "instances": [i.to_json() for i in r.constraints.instances],
                       "status": r.status, "violations": r.violations, "leaves": [first, count]})
        first += count
    body = [Array("traj.segment", "<i4", (), lambda: (np.asarray(r.leaves["segment"]) for r in results)),
            Array("traj.t", "<f8", (2,), lambda: (np.stack([r.leaves["tlo"], r.leaves["thi"]], -1) for r in results)),
            Array("traj.state", "|u1", (len(results[0].constraints.instances),), lambda: (_states(r) for r in results))]
    more = {} if route is None else {"route": {"from": list(route[0]), "to": list(route[1])}}
    return Document(header(robot, "trajectory", pose=list(robot.pose_names), claims=claims, **more), body)
