"""Singularity certificates: per box, the search tree with the rule and sign of each leaf, or two
witness poses of opposite certified signs (``proofs.singularity`` re-checks them)."""
from __future__ import annotations

from ..engine import PROVED
from .writing import floats, pose_certificate


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


def singularity_claim(result) -> dict:
    claim = {"box": [[float(a), float(b)] for a, b in zip(result.lo, result.hi)], "status": result.status}
    if result.box and all(isinstance(v, list) for v in result.box.values()):
        claim["requested"] = {k: [str(a), str(b)] for k, (a, b) in result.box.items()}
    if result.status == "singularity-free":
        claim["sign"] = int(result.sign)
        claim["tree"] = singularity_tree(result)
    elif result.status == "singular":
        claim["witnesses"] = {k: floats(v) for k, v in result.witnesses.items()}
    return claim


def singularity_certificate(results) -> dict:
    """Certificate for one SingularityResult or a list of them (cells)."""
    return pose_certificate("singularity", results, singularity_claim)
