"""Workspace certificates: per section (or z-slab), the domain, the paving tree with the verdict of
each leaf (inside, outside with the excluding leg, boundary) and the area bracket; for a volume,
its slabs and bracket (``proofs.workspace`` re-checks them)."""
from __future__ import annotations

from ..engine import EXCLUDED, PROVED
from .writing import header

MODEL = {"gough-stewart": "gough-stewart-workspace/1", "planar-3rpr": "planar-3rpr-workspace/1"}


def _header(result, problem):
    cert = header(result.robot, problem, MODEL[result.robot.kind])
    names = [n for n in result.robot.pose_names if n in result.robot.angle_names]
    cert["orientation"] = dict(zip(names, result.orientation))
    return cert


def paving_tree(paving) -> dict:
    """The search tree of one paving (one root of the search) as nested certificate nodes."""
    t = paving.tree

    def leaf(i):
        box = [[float(t.lo[i, 0]), float(t.hi[i, 0])], [float(t.lo[i, 1]), float(t.hi[i, 1])]]
        if t.kind[i] == PROVED:
            return {"leaf": "inside", "box": box}
        if t.kind[i] == EXCLUDED:
            return {"leaf": "outside", "leg": int(t.evidence_of(i, ("leg",))["leg"]) + 1, "box": box}
        return {"leaf": "boundary", "box": box}

    return t.nested(paving.root, leaf)


def section_certificate(result) -> dict:
    """Certificate of one workspace section (``workspace.SectionResult``)."""
    cert = _header(result, "workspace-section")
    claim = {} if result.z is None else {"z": result.z}
    if result.domain is None:
        claim.update({"domain": "empty", "tree": None, "area": {"inner": 0.0, "outer": 0.0}})
    else:
        claim.update({"domain": [[float(result.domain[0][k]), float(result.domain[1][k])] for k in range(2)],
                      "tree": paving_tree(result.paving),
                      "area": {"inner": result.inner, "outer": result.outer}})
    cert["claims"] = [claim]
    return cert


def volume_certificate(result) -> dict:
    """Certificate of a workspace volume bracket (``workspace.VolumeResult``): one claim per slab."""
    cert = _header(result, "workspace-volume")
    cert["requested"] = {"z": list(result.z_range)}
    claims = []
    for k, (dom, pav) in enumerate(zip(result.domains, result.pavings)):
        claim = {"slab": [float(result.bounds[k]), float(result.bounds[k + 1])]}
        if dom is None:
            claim.update({"domain": "empty", "tree": None, "area": {"inner": 0.0, "outer": 0.0}})
        else:
            claim.update({"domain": [[float(dom[0][j]), float(dom[1][j])] for j in range(2)],
                          "tree": paving_tree(pav),
                          "area": {"inner": pav.inner_area(), "outer": pav.outer_area()}})
        claims.append(claim)
    cert["claims"] = claims
    vin, vout = result.volume()
    cert["volume"] = {"inner": vin, "outer": vout}
    return cert
