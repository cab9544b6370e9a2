"""Workspace certificates (``docs/certificates.md``): per section (or z-slab), the domain, the area
bracket (header) and the paving tree with the verdict of each leaf: 0 inside, 1 outside (the
excluding leg, 1-based, in ``tree.index``), 2 boundary; for a volume, its slabs and bracket
(``proofs.workspace`` re-checks them)."""
from __future__ import annotations

import numpy as np

from ..engine import EXCLUDED, PROVED
from .forest import Forest, Rules
from .writing import Document, header

MODEL = {"gough-stewart": "gough-stewart-workspace/1", "planar-3rpr": "planar-3rpr-workspace/1"}


def _code(t, ids):
    return np.where(t.kind[ids] == PROVED, 0, np.where(t.kind[ids] == EXCLUDED, 1, 2))


def _legs(t, ids, c):
    m = ids[(t.kind[ids] == EXCLUDED)]
    return (t.evidence_values("leg", m).astype(np.int32) + 1) if len(m) else np.zeros(0, np.int32)


RULES = Rules(_code, {"tree.index": ("<i4", (), _legs)})


def _claim(domain, paving, inner, outer):
    if domain is None:
        return {"domain": "empty", "tree": None, "area": {"inner": 0.0, "outer": 0.0}}
    return {"domain": [[float(domain[0][k]), float(domain[1][k])] for k in range(2)], "tree": True,
            "area": {"inner": inner, "outer": outer}}


def _document(result, problem, claims, roots, **fields):
    names = [n for n in result.robot.pose_names if n in result.robot.angle_names]
    hdr = header(result.robot, problem, MODEL[result.robot.kind], orientation=dict(zip(names, result.orientation)),
                 claims=claims, **fields)
    return Document(hdr, Forest([(p.tree, p.root, RULES) for p in roots], 2).arrays())


def section_certificate(result) -> Document:
    """The certificate of one workspace section (``workspace.SectionResult``)."""
    claim = {} if result.z is None else {"z": result.z}
    claim.update(_claim(result.domain, result.paving, result.inner, result.outer))
    return _document(result, "workspace-section", [claim], [result.paving] if result.domain is not None else [])


def volume_certificate(result) -> Document:
    """The certificate of a workspace volume bracket (``workspace.VolumeResult``): one claim per slab."""
    claims, roots = [], []
    for k, (dom, pav) in enumerate(zip(result.domains, result.pavings)):
        claim = {"slab": [float(result.bounds[k]), float(result.bounds[k + 1])]}
        claim.update(_claim(dom, pav, pav.inner_area() if dom is not None else 0.0,
                            pav.outer_area() if dom is not None else 0.0))
        claims.append(claim)
        if dom is not None:
            roots.append(pav)
    vin, vout = result.volume()
    return _document(result, "workspace-volume", claims, roots, requested={"z": list(result.z_range)},
                     volume={"inner": vin, "outer": vout})
