"""Test helpers for certificates (format version 2): an editable copy of a certificate, its trees'
nodes and evidence rows, and files packed or damaged on purpose.

``Doc(source)`` copies the header and body arrays of a certkin document (``result.certificate()``)
or of a file; tests edit them and ``check()`` them as a forger would (hashes recomputed), or
``write(path, rehash=False)`` them as damage would leave them.
"""
from __future__ import annotations

import copy
import hashlib
import json
import zipfile

import numpy as np

import proofs
from proofs import container, fk, singularity, workspace

TABLES = {"singularity": ({c: (n, {"tree.flags": int(c == 2)}) for c, n in singularity.RULES.items()}, {}),
          "forward-kinematics": (fk.LEAVES, fk.CONTRACTIONS),
          "workspace-section": (workspace.LEAVES, {}), "workspace-volume": (workspace.LEAVES, {})}


def checked(result):
    """Re-check a result's certificate with the independent checker; the report (asserted OK)."""
    report = proofs.check(result.certificate())
    assert report.ok, report.step
    return report


class Doc:
    """An editable copy of a certificate: ``header`` (dict) and ``arrays`` ({name: numpy array})."""

    def __init__(self, source):
        if hasattr(source, "header") and hasattr(source, "arrays"):
            header, arrays = source.header, source.arrays
        else:
            cert = container.read(source)
            header, arrays = cert.header, {n: cert.array(n) for n in cert.header["arrays"]}
        self.header = copy.deepcopy(header)
        self.arrays = {n: np.array(a, copy=True) for n, a in arrays.items()}

    def copy(self):
        return Doc(self)

    def check(self, robot=None):
        return proofs.check(self, robot=robot)

    def claim(self, k=0):
        return self.header["claims"][k]

    def robot_edited(self):
        """After an edit of ``header["robot"]``: its geometry hash recomputed (a forger would)."""
        self.header["geometry_sha256"] = proofs.geometry_sha256(self.header["robot"])
        return self

    # ----- trees
    def nodes(self, kind, code=None):
        """Node numbers (breadth-first order) of a kind (0 split, 1 cut, 2 contraction, 3 leaf) and code."""
        m = self.arrays["tree.kind"] == kind
        if code is not None:
            m &= np.isin(self.arrays["tree.code"], np.atleast_1d(code))
        return np.nonzero(m)[0]

    def row(self, name, node, k=0):
        """Row k of evidence array ``name`` used by ``node``."""
        kind, code = self.arrays["tree.kind"], self.arrays["tree.code"]
        if name == "tree.box":
            uses = (kind == 2).astype(int)
        elif name == "tree.cut":
            uses = (kind == 1).astype(int)
        else:
            leaves, contractions = TABLES[self.header["problem"]]
            uses = np.zeros(len(kind), int)
            for table, kd in ((leaves, 3), (contractions, 2)):
                for c, (_, used) in table.items():
                    uses[(kind == kd) & (code == c)] += used.get(name, 0)
        assert uses[node] > k, f"node {node} has no row {k} of {name}"
        return int(np.sum(uses[:node])) + k

    # ----- files
    def write(self, path, rehash=True):
        """Write a version-2 archive; ``rehash=False`` keeps the header's hashes as they are."""
        raws = {n: np.ascontiguousarray(a).tobytes() for n, a in self.arrays.items()}
        header = dict(self.header)
        if rehash:
            body = hashlib.sha256()
            header["arrays"] = {}
            for n, a in self.arrays.items():
                header["arrays"][n] = {"dtype": np.ascontiguousarray(a).dtype.str, "shape": list(a.shape),
                                       "sha256": hashlib.sha256(raws[n]).hexdigest()}
                body.update(raws[n])
            header["body_sha256"] = body.hexdigest()
            header["geometry_sha256"] = proofs.geometry_sha256(header["robot"])
        with zipfile.ZipFile(path, "w") as z:
            z.writestr(zipfile.ZipInfo("header.json"), json.dumps(header), compress_type=zipfile.ZIP_STORED)
            for n, raw in raws.items():
                z.writestr(n + ".bin", raw, compress_type=zipfile.ZIP_DEFLATED)
        return path


def document(header, arrays):
    """A hand-written certificate (header without hashes, arrays) as an editable ``Doc``."""
    doc = Doc.__new__(Doc)
    doc.header = dict(copy.deepcopy(header), geometry_sha256=proofs.geometry_sha256(header["robot"]))
    doc.arrays = {n: np.array(a, copy=True) for n, a in arrays.items()}
    return doc


def tree_arrays(nested, d):
    """Hand-written trees for tests: nested tuples ``("split", dim, lower, upper)``, ``("cut", dim, at,
    lower, upper)`` or ``("leaf", code, {array: [rows]})`` (one per root) → the breadth-first arrays."""
    kinds, codes, cuts, ev = [], [], [], {}
    level = list(nested)
    while level:
        nxt = []
        for node in level:
            if node[0] == "split":
                kinds.append(0), codes.append(node[1])
                nxt += [node[2], node[3]]
            elif node[0] == "cut":
                kinds.append(1), codes.append(node[1]), cuts.append(node[2])
                nxt += [node[3], node[4]]
            else:
                kinds.append(3), codes.append(node[1])
                for name, rows in (node[2] if len(node) > 2 else {}).items():
                    ev.setdefault(name, []).extend(rows)
        level = nxt
    out = {"tree.kind": np.array(kinds, np.uint8), "tree.code": np.array(codes, np.uint8),
           "tree.cut": np.array(cuts, np.float64), "tree.box": np.zeros((0, d, 2), np.uint64)}
    for name, rows in ev.items():
        out[name] = np.array(rows, np.int8 if name == "tree.flags" else np.int32)
    return out
