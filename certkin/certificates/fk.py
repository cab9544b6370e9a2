"""Forward-kinematics certificates: per set of leg lengths, the domain, every solution box with its
Krawczyk matrix, the clusters (regions of unresolved postures), and the search tree with the
evidence of each leaf and contraction (``proofs.fk`` re-checks them)."""
from __future__ import annotations

import numpy as np

from ..engine import EXCLUDED, PROVED
from .writing import FORMAT, VERSION, box_json


def fk_certificate(results) -> dict:
    """Certificate for one FKResult or a list of them (one claim per set of leg lengths)."""
    if not isinstance(results, (list, tuple)):
        results = [results]
    # a search too large to keep whole forgot its excluded leaves: the same query again, tree kept
    results = [r if getattr(r, "recorded", None) is None else r.recorded() for r in results]
    r0 = results[0]
    cert = {"format": FORMAT, "version": VERSION, "problem": "forward-kinematics", "robot": r0.robot.to_dict(),
            "model": r0.system.model_name, "unknowns": list(r0.system.unknowns)}
    cert["claims"] = [fk_claim(r) for r in results]
    return cert


def fk_claim(result) -> dict:
    """The claim of one FK result: domain, solutions with their Krawczyk matrices, and the search tree."""
    if np.any(result.domain[0] > result.domain[1]):  # the leg-length balls do not meet: no posture at all
        return {"lengths": list(result.lengths), "domain": "empty", "covers": "all-postures", "complete": True,
                "solutions": [], "tree": None}
    claim = {"lengths": list(result.lengths), "domain": box_json(*result.domain),
             "covers": "box" if result.user_domain or result.tracked else "all-postures",
             "complete": bool(result.complete)}
    sols = result.all_solutions
    claim["solutions"] = [{"box": box_json(s["box"].lo, s["box"].hi), "C": np.asarray(s["C"]).tolist()} for s in sols]
    if result.clusters:
        claim["clusters"] = [box_json(c["box"].lo, c["box"].hi) for c in result.clusters]
    if result.tracked:  # one Krawczyk proof on the whole box: exactly one posture there
        claim["tree"] = {"leaf": "krawczyk-unique", "box": claim["domain"], "C": np.asarray(result.track_C).tolist(),
                         "solution": 0}
        return claim
    if result.tree is None:
        claim["tree"] = {"leaf": "undecided", "box": claim["domain"]}
        return claim
    tree = result.tree

    def leaf(i):
        box = box_json(tree.lo[i], tree.hi[i])
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
                out["star"] = box_json(*star)
            if "outside" in proof:
                olo, ohi, oC = proof["outside"]
                out["outside"] = {"box": box_json(olo, ohi), "C": np.asarray(oC).tolist()}
            else:
                out["solution"] = int(proof["solution"])
                if proof["twin"]:
                    out["twin"] = True
            return out
        if int(i) in result.cluster_of:      # nothing proved: the leaf lies in a region the claim lists
            return {"leaf": "cluster", "box": box, "cluster": result.cluster_of[int(i)]}
        return {"leaf": "undecided", "box": box}

    def contraction(i):
        name = tree.reason_name(i)
        child = int(tree.first_child[i])
        out = {"contract": name, "box": box_json(tree.lo[child], tree.hi[child])}
        out.update(tree.evidence_of(i, ("C",) if name in ("krawczyk", "slope", "slope-gs") else ("P",)))
        return out

    claim["tree"] = tree.nested(result.node, leaf, contraction)
    return claim
