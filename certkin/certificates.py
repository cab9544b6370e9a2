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

from .engine import PROVED

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
