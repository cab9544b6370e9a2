"""Writing certificates (format: ``docs/certificates.md``).

A certificate states the robot (exact decimals), the model equations by
name, the claimed boxes and, for each, the evidence: the search tree with
the rule that decided each leaf, or two witness poses.  The checker in
``proofs`` re-verifies it without using certkin.
"""
from __future__ import annotations

import json
import os
from pathlib import Path
import tempfile

import numpy as np

from .engine import EXCLUDED, PROVED

FORMAT = "certkin-certificate"
VERSION = 1


def _floats(a):
    return [float(v) for v in a]


def singularity_tree(result) -> dict:
    """The search tree of one singularity result as nested certificate nodes."""
    tree = result.tree

    def leaf(i):
        out = {"leaf": tree.reason_name(i) if tree.kind[i] == PROVED else "undecided",
               "box": [[float(a), float(b)] for a, b in zip(tree.lo[i], tree.hi[i])]}
        if tree.kind[i] == PROVED:
            ev = tree.evidence_of(i)
            out["sign"] = int(ev["sign"])
            if out["leaf"] == "monotone":
                out["monotone"] = [int(v) for v in ev["monotone"]]
        return out

    return tree.nested(result.node, leaf)


def fk_certificate(results) -> dict:
    """Certificate for one FKResult or a list of them (one claim per set of leg lengths)."""
    if not isinstance(results, (list, tuple)):
        results = [results]
    r0 = results[0]
    cert = {"format": FORMAT, "version": VERSION, "problem": "forward-kinematics", "robot": r0.robot.to_dict(),
            "model": r0.system.model_name, "unknowns": list(r0.system.unknowns)}
    cert["claims"] = [fk_claim(r) for r in results]
    return cert


def _box(lo, hi):
    return [[float(a), float(b)] for a, b in zip(lo, hi)]


def fk_claim(result) -> dict:
    """The claim of one FK result: domain, solutions with their Krawczyk matrices, and the search tree."""
    if np.any(result.domain[0] > result.domain[1]):  # the leg-length balls do not meet: no posture at all
        return {"lengths": list(result.lengths), "domain": "empty", "covers": "all-postures", "complete": True,
                "solutions": [], "tree": None}
    claim = {"lengths": list(result.lengths), "domain": _box(*result.domain),
             "covers": "box" if result.user_domain or result.tracked else "all-postures",
             "complete": bool(result.complete)}
    sols = result.all_solutions
    claim["solutions"] = [{"box": _box(s["box"].lo, s["box"].hi), "C": np.asarray(s["C"]).tolist()} for s in sols]
    if result.tracked:  # one Krawczyk proof on the whole box: exactly one posture there
        claim["tree"] = {"leaf": "krawczyk-unique", "box": claim["domain"], "C": np.asarray(result.track_C).tolist(),
                         "solution": 0}
        return claim
    if result.tree is None:
        claim["tree"] = {"leaf": "undecided", "box": claim["domain"]}
        return claim
    tree = result.tree

    def leaf(i):
        box = _box(tree.lo[i], tree.hi[i])
        if tree.kind[i] == EXCLUDED:
            name = tree.reason_name(i)
            out = {"leaf": name, "box": box}
            if name == "equation":
                out["equation"] = int(tree.evidence_of(i, ("equation",))["equation"])
            elif name in ("krawczyk-empty", "slope-empty", "slope-gs-empty"):
                out["C"] = tree.evidence_of(i, ("C",))["C"]
            elif name == "hc4-empty":
                pass                          # no evidence: the checker repeats the contraction
            else:
                out["P"] = tree.evidence_of(i, ("P",))["P"]
            return out
        if tree.kind[i] == PROVED:
            proof = result.leaf_proofs.get(int(i), {"undecided": True})
            if proof.get("undecided"):
                return {"leaf": "undecided", "box": box}
            out = {"leaf": "krawczyk-unique", "box": box, "C": tree.evidence_of(i, ("C",))["C"]}
            star = proof["star"]
            if np.any(star[0] != tree.lo[i]) or np.any(star[1] != tree.hi[i]):
                out["star"] = _box(*star)
            if "outside" in proof:
                olo, ohi, oC = proof["outside"]
                out["outside"] = {"box": _box(olo, ohi), "C": np.asarray(oC).tolist()}
            else:
                out["solution"] = int(proof["solution"])
                if proof["twin"]:
                    out["twin"] = True
            return out
        return {"leaf": "undecided", "box": box}

    def contraction(i):
        name = tree.reason_name(i)
        child = int(tree.first_child[i])
        out = {"contract": name, "box": _box(tree.lo[child], tree.hi[child])}
        out.update(tree.evidence_of(i, ("C",) if name in ("krawczyk", "slope", "slope-gs") else ("P",)))
        return out

    claim["tree"] = tree.nested(result.node, leaf, contraction)
    return claim


def header(robot, problem: str) -> dict:
    return {"format": FORMAT, "version": VERSION, "problem": problem,
            "robot": robot.to_dict(), "model": f"{robot.model_name}/1", "pose": list(robot.pose_names)}


def singularity_claim(result) -> dict:
    claim = {"box": [[float(a), float(b)] for a, b in zip(result.lo, result.hi)], "status": result.status}
    if result.box and all(isinstance(v, list) for v in result.box.values()):
        claim["requested"] = {k: [str(a), str(b)] for k, (a, b) in result.box.items()}
    if result.status == "singularity-free":
        claim["sign"] = int(result.sign)
        claim["tree"] = singularity_tree(result)
    elif result.status == "singular":
        claim["witnesses"] = {k: _floats(v) for k, v in result.witnesses.items()}
    return claim


def singularity_certificate(results) -> dict:
    """Certificate for one SingularityResult or a list of them (cells)."""
    if not isinstance(results, (list, tuple)):
        results = [results]
    cert = header(results[0].robot, "singularity")
    cert["claims"] = [singularity_claim(r) for r in results]
    return cert


def write_json(path, document) -> None:
    """Write a JSON file atomically: nothing half-written is left on failure."""
    write_text(path, json.dumps(document, separators=(",", ":")) + "\n")


def write_text(path, text: str) -> None:
    """Write a text file atomically (a temporary file renamed into place)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


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
    if not isinstance(results, (list, tuple)):
        results = [results]
    cert = header(results[0].robot, "trajectory")
    cert["claims"] = [trajectory_claim(r) for r in results]
    return cert
