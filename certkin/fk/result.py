"""The answer of a forward-kinematics query: every proved assembly mode, the unresolved regions,
and the tree and proofs its certificate is written from."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from intervals import Interval

from ..certificates import fk_certificate
from ..display import counted


@dataclass(repr=False)
class FKResult:
    """All real assembly modes for one set of leg lengths."""

    robot: object
    system: object
    lengths: list                       # exact texts
    domain: tuple                       # (lo, hi) of the unknowns searched
    solutions: list = field(default_factory=list)    # dicts: box (Interval of unknowns), pose, platform_points
    unresolved: list = field(default_factory=list)
    complete: bool = False
    tree: object = None
    node: int = 0
    leaf_proofs: dict = field(default_factory=dict)     # proved leaf -> {star, solution/twin | outside | undecided}
    boxes: int = 0
    seconds: float = 0.0
    tracked: bool = False
    user_domain: bool = False                           # a user domain narrowed the search
    domain_text: str | None = None                      # that domain as given ("x=a:b,...")
    track_C: np.ndarray | None = None                   # the Krawczyk matrix of a tracking proof
    all_solutions: list = field(default_factory=list)   # every proved root of the searched box (certificate order)
    filtered: list = field(default_factory=list)        # solutions outside a user domain (pose filter)
    regions: list = field(default_factory=list)         # per distinct root: X* (star, star_C), R (box, C), status
    clusters: list = field(default_factory=list)        # regions of unresolved postures (status "cluster")
    cluster_leaves: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    cluster_of: dict = field(default_factory=dict)      # cluster leaf -> its cluster
    message: str = ""                                   # what the search could not settle, in words
    recorded: object = None                             # set when the tree was not kept whole: gives the
                                                        # same query's result with its whole tree

    @property
    def status(self) -> str:
        """complete (every posture of the domain listed), tracked (the one near the previous pose), incomplete."""
        return "complete" if self.complete else "tracked" if self.tracked else "incomplete"

    def __repr__(self):
        c = len(self.clusters)
        clusters = f", {counted(c, 'cluster')} (not resolved)" if c else ""
        return (f"<FKResult {counted(len(self.solutions), 'solution')}, {self.status}{clusters}, "
                f"{len(self.unresolved)} unresolved; lengths "
                f"{','.join(self.lengths)}>")

    def to_json(self) -> dict:
        """The result as a JSON-ready dict (``json.dumps(result.to_json())``): the document of
        ``certkin fk --json``."""
        def entry(s, with_status):
            e = {"pose": {k: [float(v.lo), float(v.hi)] for k, v in s["pose"].items()},
                 "platform_points": [[[float(c.lo), float(c.hi)] for c in p] for p in s["platform_points"]]}
            return {"status": "unique", **e} if with_status else e
        out = {"problem": "forward-kinematics", "robot": self.robot.name, "kind": self.robot.kind,
               "lengths": self.lengths, "complete": self.complete,
               "solutions": [entry(s, True) for s in self.solutions]
               + [{"status": "cluster", **entry(c, False), **({"twin_of": c["twin_of"] + 1} if "twin_of" in c else {})}
                  for c in self.clusters],
               "unresolved": [entry(s, False) for s in self.unresolved],
               "stats": {"boxes": self.boxes, "seconds": round(self.seconds, 6)}, "tracked": bool(self.tracked)}
        if self.domain_text is not None:     # complete means: every posture of this domain listed
            out["domain"] = self.domain_text
        if self.message:
            out["message"] = self.message
        return out

    def certificate(self):
        """The certificate (``certificates.Document``: ``.write(path)``, or ``proofs.check`` it in memory;
        a search too large to keep whole is run again first)."""
        return fk_certificate(self)


def described(robot, poses: dict, pts: Interval) -> list[dict]:
    """Per box j: ``{"pose": robot_pose(robot, poses at j), "platform_points": pts[j] as nested lists}``,
    the scalar intervals taken row by row from the endpoint arrays (indexing each coordinate of 2000
    unresolved boxes through ``Interval.__getitem__`` took 0.2 s)."""
    cols = {k: zip(v.lo, v.hi) for k, v in poses.items()}
    out = []
    for row_lo, row_hi in zip(pts.lo, pts.hi):
        pose = {k: Interval.from_bounds(*next(c)) for k, c in cols.items()}
        points = [[Interval.from_bounds(a, b) for a, b in zip(lo, hi)] for lo, hi in zip(row_lo, row_hi)]
        out.append({"pose": robot_pose(robot, pose), "platform_points": points})
    return out


def robot_pose(robot, pose):
    """The pose in the robot's own variables, from the enclosures of ``FKSystem.pose`` (spherical
    robots with tilt-and-torsion angles: sigma = phi1 + phi3)."""
    if "sigma" in robot.pose_names:
        return {"phi1": pose["phi1"], "phi2": pose["phi2"], "sigma": pose["phi1"] + pose["phi3"]}
    return pose
