"""Singularity claims (``"problem": "singularity"``, docs/certificates.md "Singularity claims"; docs/soundness.md §7).

``singularity-free``: the leaves of the claim's tree tile its ``box`` and each leaf's rule (``RULES``) re-proves
sign(det A) = ``sign`` on it (bisected up to ``MAX_DEPTH`` levels when the checker's own enclosure does not decide it;
a rule proving −sign refutes it).  ``singular``: two witness poses in the box and the exact ``requested`` box, det(A)
proved > 0 at one and < 0 at the other, so that it vanishes between them (intermediate value theorem).  ``undecided``:
nothing is claimed."""
from __future__ import annotations

import numpy as np

from . import tree
from .arith import Iv
from .models import MODELS, Robot, each_claim, header_model
from .numbers import angle, enclose, inside, real
from .report import Rejected

RULES = {0: "natural", 1: "centred", 2: "monotone"}
MAX_DEPTH = 6


def check(cert, report) -> None:
    h = cert.header
    model = header_model(h, MODELS, lambda m: m.kind, "pose", lambda m: m.pose)
    robot, d, counts = Robot(model, h["robot"]), len(model.pose), report.checked
    roots, signs, status_count, witnesses = [], [], {}, []
    for k, (where, claim) in enumerate(each_claim(h["claims"])):
        status = claim.get("status")
        if status not in ("singularity-free", "singular", "undecided"):
            raise Rejected(f"{where}.status: unknown status {status!r}")
        status_count[status] = status_count.get(status, 0) + 1
        if status == "undecided":
            counts["undecided"] += 1
            continue
        lo, hi = tree.read_box(claim.get("box"), d, f"{where}.box")
        req = _requested(claim.get("requested"), model.pose, lo, hi, f"{where}.requested")
        if status == "singular":
            witnesses.append(_witnesses(model.pose, claim.get("witnesses"), req, lo, hi, f"{where}.witnesses"))
            counts["witnesses"] += 1
            continue
        s = claim.get("sign")
        if s not in (1, -1) or isinstance(s, bool):
            raise Rejected(f"{where}.sign: expected 1 or -1, got {s!r}")
        roots.append((k, lo, hi, claim.get("tree")))
        signs.append(s)
    if witnesses:                        # all witness poses in one batch: +, − per claim
        got = robot.det(np.concatenate([w[0] for w in witnesses]), np.concatenate([w[1] for w in witnesses])).sign().reshape(-1, 2)
        bad = np.nonzero(np.any(got != [1, -1], axis=1))[0]
        if len(bad):
            where, k = witnesses[bad[0]][2], int(got[bad[0], 0] == 1)
            raise Rejected(f"{where}.{('positive', 'negative')[k]}: det(A) not proved {('> 0', '< 0')[k]}")
    if any(t is not True for *_, t in roots):
        raise Rejected("claims: a singularity-free claim has \"tree\": true (its tree is in the body)")
    forest = tree.Forest(cert, d, [r[1] for r in roots], [r[2] for r in roots], {c: (n, {"tree.flags": 2 == c})
                         for c, n in RULES.items()}, {}, {"tree.flags": ((d,), ("|i1",))},
                         [f"claims[{r[0]}].tree" for r in roots])
    flags = forest.evidence["tree.flags"]
    if np.any((flags < -1) | (flags > 1)):
        raise Rejected("tree.flags: monotonicity flags must be -1, 0 or 1")
    signs, claim_of = np.array(signs or [0]), np.array([r[0] for r in roots] or [0])
    scale = np.array([np.where(r[2] > r[1], r[2] - r[1], 1.0) for r in roots] or [np.ones(d)])

    def visit(kind, code, ids, lo, hi, root, child):
        f = forest.rows("tree.flags", ids) if code == 2 else None
        counts["pieces"] += _prove(robot, code, ids, lo, hi, signs[root], f, scale[root], claim_of[root])
        counts["leaves"] += len(ids)

    forest.walk(visit, report.progress)
    text = ", ".join(f"{n} {s}" for s, n in status_count.items())
    first = h["claims"][0]
    req = first.get("requested")         # over the float box's variables (an undecided claim's are printed as they are)
    box = {**dict(zip(model.pose, first["box"] if isinstance(first.get("box"), list) else [])), **(req if type(req) is dict else {})}
    report.about["question"] = (f"does det(A) vanish in {len(h['claims'])} box(es) of poses; first: " + ", ".join(
        f"{v} in [{', '.join(map(str, ab))}]" if isinstance(ab, list) else f"{v} = {ab}" for v, ab in box.items()))
    if len(h["claims"]) > 1:
        return report.proved.append(f"{len(h['claims'])} boxes of poses: {text}")
    if first["status"] == "singular":
        w = first["witnesses"]
        return report.proved.append(f"singular: det(A) > 0 at ({', '.join(map(str, w['positive']))}), "
                                    f"< 0 at ({', '.join(map(str, w['negative']))}): it vanishes between")
    report.proved.append(f"{first['status']}" + (f": det(A) {'> 0' if first['sign'] > 0 else '< 0'} on the whole box "
                                                 f"({counts['leaves']} leaves)" if first["status"] != "undecided" else ""))


def _requested(req, pose, lo, hi, where):
    """The exact requested box (decimal texts per variable), checked to lie inside the float box."""
    if req is None:
        return None
    if not isinstance(req, dict):
        raise Rejected(f"{where}: expected an object")
    for name, value in req.items():
        if name not in pose:
            raise Rejected(f"{where}: unknown pose variable {name!r}")
        if not isinstance(value, list) or len(value) != 2:
            raise Rejected(f"{where}.{name}: expected [lo, hi] exact decimals")
        i = pose.index(name)
        for v in value:
            if not inside(v, lo[i], hi[i], f"{where}.{name}"):
                raise Rejected(f"{where}.{name}: {v!r} is not inside the box [{float(lo[i])!r}, {float(hi[i])!r}]")
    return req


def _witnesses(pose, wit, req, lo, hi, where):
    """The two witness poses as boxes (lo, hi) (2, d), checked to lie in the box and in the exact requested
    box.  A coordinate is a float (its exact value) or an exact decimal string (``deg`` allowed),
    enclosed: det(A) of one sign over the enclosure has that sign at the exact pose."""
    if not isinstance(wit, dict):
        raise Rejected(f"{where}: expected {{'positive': pose, 'negative': pose}}")
    out = []
    for key in ("positive", "negative"):
        p = wit.get(key)
        if not isinstance(p, list) or len(p) != len(pose):
            raise Rejected(f"{where}.{key}: expected a pose of {len(pose)} values")
        x = [enclose(v, f"{where}.{key}[{i}]", True) if isinstance(v, str) else Iv(real(v, f"{where}.{key}[{i}]"))
             for i, v in enumerate(p)]
        xl, xh = np.array([float(v.lo) for v in x]), np.array([float(v.hi) for v in x])
        if not np.all((lo <= xl) & (xh <= hi)):
            raise Rejected(f"{where}.{key}: pose outside the box")
        for name, (a, b) in (req or {}).items():
            i = pose.index(name)
            if not (_le(a, p[i], xl[i], where) and _le(p[i], b, xh[i], where, True)):
                raise Rejected(f"{where}.{key}: {name} = {p[i]!r} is outside the requested [{a}, {b}]")
        out.append((xl, xh))
    return np.array([o[0] for o in out]), np.array([o[1] for o in out]), where


def _le(a, b, x, where, flip=False):
    """a ≤ b exactly, for decimal texts (``deg`` allowed) and floats (``x``: the float bound of the witness)."""
    if isinstance(b if not flip else a, str):
        (qa, da), (qb, db) = angle(a, where), angle(b, where)
        return qa <= qb if da == db else bool(enclose(a, where, True).hi <= enclose(b, where, True).lo)
    return inside(a, -np.inf, x, where) if not flip else inside(b, x, np.inf, where)


def _rule(robot, code, lo, hi, s, flags):
    """Per box: s (proved), −s (refuted: det has the other sign there) or 0 (undecided)."""
    if code == 0:
        return robot.det(lo, hi).sign()
    D, grad = robot.det_gradient(lo, hi)
    if code == 1:
        return _centred(robot, lo, hi, D, grad)
    got = np.where(D.sign() == -s, -s, 0)
    mono = np.all(np.where(flags > 0, grad.lo >= 0, np.where(flags < 0, grad.hi <= 0, True)), axis=1)
    face = (flags * s[:, None] > 0, flags * s[:, None] < 0)          # at lo, at hi
    flo, fhi = np.where(face[1], hi, lo), np.where(face[0], lo, hi)
    Fd = robot.det(flo, fhi).sign()
    todo = (Fd != s) & mono & (got == 0)
    if todo.any():
        Fd[todo] = _centred(robot, flo[todo], fhi[todo], *robot.det_gradient(flo[todo], fhi[todo]))
    return np.where(got != 0, got, np.where(D.sign() == s, s, np.where(mono & (Fd == s), s, 0)))


def _centred(robot, lo, hi, D, grad):
    m = np.minimum(np.maximum(0.5 * lo + 0.5 * hi, lo), hi)
    form = robot.det(m, m)
    for i in range(lo.shape[1]):
        form = form + grad[:, i] * (Iv(lo[:, i], hi[:, i]) - m[:, i])
    s = form.sign()
    return np.where(s != 0, s, D.sign())


def _prove(robot, code, ids, lo, hi, s, flags, scale, claim):
    """Prove the rule on every leaf, bisecting undecided ones; returns the extra pieces used."""
    pieces, depth, owner = 0, 0, np.arange(len(ids))
    while len(lo):
        got = _rule(robot, code, lo, hi, s, flags)
        bad = got == -s
        if bad.any() or (depth == MAX_DEPTH and np.any(got == 0)):
            i = int(np.nonzero(bad | (got == 0))[0][0])
            box = ", ".join(f"{float(a)!r}:{float(b)!r}" for a, b in zip(lo[i], hi[i]))
            what = (f"det(A) has sign {got[i]} on [{box}], not {s[i]}" if got[i] else
                    f"sign {s[i]} not proved on [{box}] (also after bisecting {MAX_DEPTH} levels)")
            raise Rejected(f"claims[{claim[owner[i]]}].tree: node {ids[owner[i]]} (leaf): {RULES[code]} rule: {what}")
        open_ = got == 0
        if not open_.any():
            break
        lo, hi, s, owner = lo[open_], hi[open_], s[open_], owner[open_]
        flags = None if flags is None else flags[open_]
        halves_lo, halves_hi, strictly_inside = tree.halves(lo, hi, scale[owner])
        if not strictly_inside:
            depth = MAX_DEPTH
            continue
        pieces += len(lo)
        lo, hi, s, owner = halves_lo, halves_hi, np.concatenate([s, s]), np.concatenate([owner, owner])
        flags = None if flags is None else np.concatenate([flags, flags])
        depth += 1
    return pieces
