"""Singularity claims (``"problem": "singularity"``, docs/certificates.md).

- ``singularity-free``: the tree's boxes are derived from the claim's ``box``
  (a split [dim, at] needs lo < at < hi and gives the lower and upper parts),
  so the leaves tile the box exactly; every leaf's ``box`` must equal its
  derived box, its ``sign`` the claim's ``sign``, and its rule must re-prove
  that sign (``rules.prove``).  det(A) then has that sign on the whole box.
- ``singular``: two poses of the box with det(A) proved > 0 and < 0; det
  vanishes on the segment between them (intermediate value theorem), which
  lies in the convex box.
- ``undecided``: nothing is claimed and nothing is checked.

The optional ``requested`` exact decimals must lie inside ``box``.
"""
from __future__ import annotations

from . import rules, tree
from .numbers import inside, real, sign
from .report import Rejected


def check_claims(robot, claims, counts: dict) -> None:
    for k, claim in enumerate(claims):
        _claim(robot, claim, f"claims[{k}]", counts)


def _claim(robot, claim, where, counts):
    if not isinstance(claim, dict):
        raise Rejected(f"{where}: expected an object")
    status = claim.get("status")
    if status == "undecided":
        counts["undecided"] += 1
        return
    if status not in ("singularity-free", "singular"):
        raise Rejected(f"{where}.status: unknown status {status!r}")
    pose = robot.model.pose
    box = read_box(claim.get("box"), len(pose), f"{where}.box")
    if "requested" in claim:
        _requested(claim["requested"], pose, box, f"{where}.requested")
    if status == "singularity-free":
        s = claim.get("sign")
        if s not in (1, -1) or isinstance(s, bool):
            raise Rejected(f"{where}.sign: expected 1 or -1, got {s!r}")
        _tree(robot, claim.get("tree"), box, s, f"{where}.tree", counts)
    else:
        _witnesses(robot, claim.get("witnesses"), box, f"{where}.witnesses")
        counts["witnesses"] += 1


def read_box(value, dims: int, where: str):
    """A box: ``dims`` pairs [lo, hi] of exact floats with lo <= hi."""
    if not isinstance(value, list) or len(value) != dims:
        raise Rejected(f"{where}: expected {dims} intervals [lo, hi]")
    box = []
    for i, pair in enumerate(value):
        if not isinstance(pair, list) or len(pair) != 2:
            raise Rejected(f"{where}[{i}]: expected [lo, hi]")
        lo, hi = real(pair[0], f"{where}[{i}]"), real(pair[1], f"{where}[{i}]")
        if not lo <= hi:
            raise Rejected(f"{where}[{i}]: lo > hi")
        box.append((lo, hi))
    return box


def _requested(req, pose, box, where):
    if not isinstance(req, dict):
        raise Rejected(f"{where}: expected an object")
    for name, value in req.items():
        if name not in pose:
            raise Rejected(f"{where}: unknown pose variable {name!r}")
        if not isinstance(value, list) or len(value) != 2:
            raise Rejected(f"{where}.{name}: expected [lo, hi] exact decimals")
        lo, hi = box[pose.index(name)]
        for v in value:
            if not inside(v, lo, hi, f"{where}.{name}"):
                raise Rejected(f"{where}.{name}: {v!r} is not inside the box [{lo!r}, {hi!r}]")


def _tree(robot, root, box, s, where, counts):
    scale = [hi - lo for lo, hi in box]
    dims = len(box)
    stack = [(root, box, ())]
    while stack:
        node, nbox, path = stack.pop()
        at_path = tree.label(where, node, path)
        if "split" in node:
            (c0, lower), (c1, upper) = tree.split(node, nbox, at_path)
            stack.append((c1, upper, path + (1,)))
            stack.append((c0, lower, path + (0,)))
        elif "leaf" in node:
            rule, flags = rules.parse(node, dims, at_path)
            if read_box(node.get("box"), dims, f"{at_path}: box") != nbox:
                raise Rejected(f"{at_path}: box does not match the derived box")
            if node.get("sign") != s or isinstance(node.get("sign"), bool):
                raise Rejected(f"{at_path}: sign {node.get('sign')!r} differs from the claim's sign {s}")
            try:
                counts["pieces"] += rules.prove(robot, rule, nbox, s, flags, scale) - 1
            except rules.NotProved as exc:
                raise Rejected(f"{at_path}: {node['leaf']} rule: {exc}") from None
            counts["leaves"] += 1
        else:
            raise Rejected(f"{at_path}: neither a split nor a leaf")


def _witnesses(robot, wit, box, where):
    if not isinstance(wit, dict):
        raise Rejected(f"{where}: expected {{'positive': pose, 'negative': pose}}")
    for key, want, text in (("positive", 1, "> 0"), ("negative", -1, "< 0")):
        pose = wit.get(key)
        if not isinstance(pose, list) or len(pose) != len(box):
            raise Rejected(f"{where}.{key}: expected a pose of {len(box)} numbers")
        point = [real(v, f"{where}.{key}[{i}]") for i, v in enumerate(pose)]
        if not all(lo <= x <= hi for x, (lo, hi) in zip(point, box)):
            raise Rejected(f"{where}.{key}: pose outside the box")
        if sign(robot.det([(x, x) for x in point])) != want:
            raise Rejected(f"{where}.{key}: det(A) not proved {text}")
