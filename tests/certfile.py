"""Test helpers for version-2 certificate files: pack a header and arrays, read them back, rewrite a file.

``pack`` is a plain writer (whole arrays in memory) used to forge and damage files
in tests; certificates proper are written by certkin.  ``from_v1`` turns a
version-1 document into a version-2 file through the checker's own v1 reader.
"""
from __future__ import annotations

import hashlib
import json
import zipfile
from decimal import ROUND_CEILING, ROUND_FLOOR, Decimal

import numpy as np

from proofs import checker, container, fk, singularity, trajectory, tree


def pack(path, header, arrays, rehash=True):
    """Write header + arrays as a version-2 archive; ``rehash=False`` keeps the header's hashes as they are."""
    raws = {name: np.ascontiguousarray(a).tobytes() for name, a in arrays.items()}
    header = dict(header)
    if rehash:
        body = hashlib.sha256()
        header["arrays"] = {}
        for name, a in arrays.items():
            a = np.ascontiguousarray(a)
            header["arrays"][name] = {"dtype": a.dtype.str, "shape": list(a.shape),
                                      "sha256": hashlib.sha256(raws[name]).hexdigest()}
            body.update(raws[name])
        header["body_sha256"] = body.hexdigest()
        header["geometry_sha256"] = checker.geometry_sha256(header["robot"])
    with zipfile.ZipFile(path, "w") as z:
        z.writestr(zipfile.ZipInfo("header.json"), json.dumps(header), compress_type=zipfile.ZIP_STORED)
        for name, raw in raws.items():
            z.writestr(name + ".bin", raw, compress_type=zipfile.ZIP_DEFLATED)
    return path


def unpack(path):
    """(header, {name: array}) of a version-2 file."""
    cert = container.read(path)
    return cert.header, {name: np.array(cert.array(name)) for name in cert.header["arrays"]}


def _decimal(v, rounding):
    d = Decimal(float(v))
    return "0" if d == 0 else format(d.quantize(Decimal(1).scaleb(d.adjusted() - 16), rounding=rounding).normalize(), "f")


def from_v1(doc, path):
    """A version-1 document (dict) as a version-2 file at ``path``."""
    cert = container.Certificate(json.loads(json.dumps(doc)))
    h = dict(cert.header, version=2)
    if h["problem"] == "forward-kinematics":
        arrays, offsets = fk._from_v1(fk.System(h["model"], h["robot"]), h["claims"])
        for name in ("tree.C", "tree.P"):
            if np.array_equal(arrays[name].astype(np.float32), arrays[name]):
                arrays[name] = arrays[name].astype(np.float32)
        claims = []
        for c, (first, count) in zip(h["claims"], offsets):
            boxes = arrays["fk.region.box"][first:first + count]
            claims.append(dict(c, regions=[first, count], tree=True if c.get("domain") != "empty" else None,
                               solutions=[{"region": j, "box": [[_decimal(a, ROUND_FLOOR), _decimal(b, ROUND_CEILING)]
                                                                for a, b in boxes[j]]} for j in range(count)]))
        h["claims"] = claims
    elif h["problem"] == "singularity":
        d = len(singularity.MODELS[h["model"]].pose)
        free = [(k, c) for k, c in enumerate(h["claims"]) if c.get("status") == "singularity-free"]
        arrays = singularity._flatten([(k, *tree.read_box(c["box"], d, ""), c["tree"]) for k, c in free],
                                      [c["sign"] for _, c in free], d)
        h["claims"] = [dict(c, tree=True) if c.get("status") == "singularity-free" else c for c in h["claims"]]
    elif h["problem"] == "trajectory":
        seg, t, st, claims = [], [], [], []
        for c in h["claims"]:
            leaves = c["leaves"]
            claims.append(dict(c, leaves=[len(seg), len(leaves["segment"])]))
            seg += leaves["segment"]
            t += leaves["t"]
            st += [[trajectory.CHARS[ch] for ch in s] for s in leaves["state"]]
        arrays = {"traj.segment": np.array(seg, np.int32), "traj.t": np.array(t, np.float64),
                  "traj.state": np.array(st, np.uint8)}
        h["claims"] = claims
    else:
        raise ValueError(h["problem"])
    arrays.pop("v1.leafbox", None)
    arrays = {k: v for k, v in arrays.items() if v.size or k in ("tree.kind", "tree.code")}
    return pack(path, h, arrays)
