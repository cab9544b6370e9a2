"""Singularity certificates (``docs/certificates.md``): per box, the exact requested box and either the
search tree whose every leaf proves the sign of det(A) (rule and monotonicity flags), or two witness
poses of opposite certified signs inside the requested box (``proofs.singularity`` re-checks them)."""
from __future__ import annotations

from decimal import Decimal
import json
import math

import numpy as np

from ..engine import PROVED
from .forest import Forest, Rules
from .writing import Document, box_json, float_text, header

CODES = {"natural": 0, "centred": 1, "monotone": 2}


def _rules(tree, d):
    lut = np.array([CODES.get(name, 255) for name in tree.reasons], np.int64)

    def code(t, ids):
        return np.where(t.kind[ids] == PROVED, lut[np.clip(t.reason[ids], 0, None)], 255)

    def flags(t, ids, c):
        m = ids[(t.kind[ids] == PROVED) & (c == CODES["monotone"])]
        return t.evidence_values("monotone", m).astype(np.int8) if len(m) else np.zeros((0, d), np.int8)

    return Rules(code, {"tree.flags": ("|i1", (d,), flags)})


def cell_claims(results) -> list:
    """``singularity_claim`` of many cells at once (their boxes as whole arrays; a cell's requested box is
    the exact decimals of its floats, each face written once): the same claims, a few µs each."""
    names = results[0].robot.pose_names
    lo = np.array([r.lo for r in results], dtype=float).tolist()
    hi = np.array([r.hi for r in results], dtype=float).tolist()
    claims = []
    for r, a, b in zip(results, lo, hi):
        if r.texts is not None or r.status == "singular":
            claims.append(singularity_claim(r))
            continue
        claim = {"box": [list(p) for p in zip(a, b)], "status": r.status,
                 "requested": {n: [float_text(u), float_text(v)] for n, u, v in zip(names, a, b)}}
        if r.status == "singularity-free":
            claim.update(sign=int(r.sign), tree=True)
        claims.append(claim)
    return claims


def singularity_claim(result) -> dict:
    claim, box = {"box": box_json(result.lo, result.hi), "status": result.status}, result.box
    if box and all(isinstance(v, list) for v in box.values()):
        claim["requested"] = {k: [str(a), str(b)] for k, (a, b) in box.items()}
    if result.status == "singularity-free":
        claim.update(sign=int(result.sign), tree=True)
    elif result.status == "singular":
        names = result.robot.pose_names        # a coordinate with an exact irrational value is written as its text
        claim["witnesses"] = {k: [result.exact_values.get(n, float(v)) for n, v in zip(names, w)]
                              for k, w in result.witnesses.items()}
    return claim


def least_header(names, grids) -> int:
    """A lower bound of the bytes the claims of the cells of a grid take in a certificate's header
    (``MAX_HEADER`` of which a checker reads).  ``grids``: per pose variable, the float faces of its
    cells (one cell per consecutive pair; a fixed variable: one pair).  A cell's claim holds its box (JSON floats) and
    requested box (the exact decimals of the same floats, ``classify_cells``), written here as
    ``Document.write`` writes them, and a status at least as long as "singular" (no sign, tree
    or witness counted)."""
    cells = math.prod(len(g) - 1 for g in grids)
    fixed = len('{"box":[],"status":"singular","requested":{}},') + 2 * (len(grids) - 1)
    total = cells * fixed
    for name, g in zip(names, grids):
        faces = [len(repr(float(v))) + len(str(Decimal(float(v)))) for v in g]
        per_cell = len(json.dumps(name)) + len('[,]:["",""]')
        total += cells // (len(g) - 1) * ((len(g) - 1) * per_cell + sum(faces[:-1]) + sum(faces[1:]))
    return total


def singularity_certificate(results) -> Document:
    """The certificate of one SingularityResult or a list of them (cells)."""
    results = results if isinstance(results, (list, tuple)) else [results]
    robot, d = results[0].robot, len(results[0].robot.pose_names)
    free = [r for r in results if r.status == "singularity-free"]
    rules = {}                                                     # one per engine tree: cells share theirs
    for r in free:
        if id(r.tree) not in rules:
            rules[id(r.tree)] = _rules(r.tree, d)
    forest = Forest([(r.tree, r.node, rules[id(r.tree)]) for r in free], d)
    hdr = header(robot, "singularity", pose=list(robot.pose_names), claims=cell_claims(results))
    return Document(hdr, forest.arrays())
