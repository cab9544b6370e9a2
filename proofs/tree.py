"""Walking a certificate's tree of boxes: node labels and the validation of splits.

Shared by the checkers of singularity, forward-kinematics and workspace
certificates.  A split node ``{"split": [dim, at], "children": [a, b]}`` of a
box is accepted only when ``dim`` is an axis of the box and ``at`` (a real
read exactly) lies strictly inside that side; the two children then cover
the box exactly: [lo, at] and [at, hi] on ``dim``, the other sides unchanged.
"""
from __future__ import annotations

from .numbers import real
from .report import Rejected


def label(where: str, node, path) -> str:
    """'<where>: leaf|node at path a/b/c' for messages; rejects a node that is not an object."""
    kind = "leaf" if isinstance(node, dict) and "leaf" in node else "node"
    at = f"{where}: {kind} at path {'/'.join(map(str, path)) or 'root'}"
    if not isinstance(node, dict):
        raise Rejected(f"{at}: expected an object")
    return at


def split(node: dict, box, at: str):
    """The two children of a split node with their boxes: [(child, box), (child, box)]."""
    dims = len(box)
    cut_spec, children = node.get("split"), node.get("children")
    if (not isinstance(cut_spec, list) or len(cut_spec) != 2 or isinstance(cut_spec[0], bool)
            or not isinstance(cut_spec[0], int) or not 0 <= cut_spec[0] < dims):
        raise Rejected(f"{at}: 'split' must be [dim, at] with 0 <= dim < {dims}")
    if not isinstance(children, list) or len(children) != 2:
        raise Rejected(f"{at}: a split needs exactly two children")
    dim, cut = cut_spec[0], real(cut_spec[1], f"{at}: split point")
    lo, hi = box[dim]
    if not lo < cut < hi:
        raise Rejected(f"{at}: split point {cut!r} not strictly inside [{lo!r}, {hi!r}] on dim {dim}")
    lower = [*box[:dim], (lo, cut), *box[dim + 1:]]
    upper = [*box[:dim], (cut, hi), *box[dim + 1:]]
    return [(children[0], lower), (children[1], upper)]
